//! Declarations and the names that use them, from the syntax trees of a document and the
//! files it imports: go to definition, find references, rename and document symbols.
//!
//! Scopes are those of the language (docs/language.md): the items of a file and of the files
//! it imports; a function's parameters and `let`s within the function; a scene's `let`s and
//! `for` variables within the scene (a `for` variable within its loop).

use sdfc_compiler::{ast, lexer, parse, FileId, SourceMap, Span};

/// Why `new` cannot be the new name of a declaration (`None` when it can): it must be one
/// name as the lexer reads it, not a keyword, and not hide a built-in function, a built-in
/// constant or the time, which the file's uses of them would then no longer reach.
pub fn not_a_new_name(new: &str) -> Option<String> {
    use sdfc_compiler::builtins;
    let (tokens, errors) = lexer::lex(FileId(0), new);
    match tokens.as_slice() {
        [(lexer::Token::Ident(name), _)] if errors.is_empty() && name == new => {}
        [(_, _)] if errors.is_empty() && new.bytes().all(|b| b.is_ascii_alphabetic()) => {
            return Some(format!("`{new}` is a keyword, not a name"))
        }
        _ => return Some(format!("`{new}` is not a name")),
    }
    if builtins::builtin(new).is_some() {
        return Some(format!(
            "`{new}` is a built-in function: a declaration of that name would hide it"
        ));
    }
    if builtins::constant(new).is_some() {
        return Some(format!(
            "`{new}` is a built-in constant: a declaration of that name would hide it"
        ));
    }
    if new == builtins::TIME {
        return Some(format!(
            "`{new}` is the time: a declaration of that name would hide it"
        ));
    }
    None
}

/// What a name is declared as.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum What {
    /// `let` at the top of a file, or in a body.
    Let,
    /// `fn`.
    Fn,
    /// `material`.
    Material,
    /// A function's parameter.
    Param,
    /// A `for` variable.
    Loop,
}

/// One declaration.
#[derive(Debug, Clone)]
pub struct Decl {
    /// The name.
    pub name: String,
    /// What it declares.
    pub what: What,
    /// The name where it is written.
    pub at: Span,
    /// The whole declaration.
    pub span: Span,
    /// Where the name can be used: `None` for an item (the whole file and its importers).
    pub scope: Option<Span>,
    /// The value's span (a `let`), for the facts of the shape it names.
    pub value: Option<Span>,
}

/// The declarations and name uses of every file of a compilation.
#[derive(Debug, Default)]
pub struct Index {
    /// Declarations, in source order per file.
    pub decls: Vec<Decl>,
    /// Every identifier token, by file.
    pub uses: Vec<(String, Span)>,
    /// The syntax tree of each file, by id.
    pub files: Vec<ast::File>,
    /// The indices in `decls` of each name's declarations (built by [`Index::new`]), so that
    /// resolving a name looks at its own declarations alone: completion and references
    /// resolve every name of a document, which over all declarations would be quadratic.
    by_name: std::collections::HashMap<String, Vec<usize>>,
}

impl Index {
    /// Parses and indexes every file of `sources`.
    pub fn new(sources: &SourceMap) -> Index {
        let mut index = Index::default();
        for f in 0..sources.len() as u32 {
            let id = FileId(f);
            let text = sources.text(id);
            let (file, _) = parse(id, text);
            let first = index.decls.len();
            for item in &file.items {
                index.item(item);
            }
            let declared: std::collections::HashSet<Span> =
                index.decls[first..].iter().map(|d| d.at).collect();
            let (tokens, _) = lexer::lex(id, text);
            for (tok, span) in tokens {
                let lexer::Token::Ident(name) = tok else {
                    continue;
                };
                // A field or argument name (`radius: 1`) names no declaration; a
                // declaration's own name (`let a: float`) is kept.
                let after = text.get(span.end as usize..).unwrap_or("").trim_start();
                let label = after.starts_with(':') && !after.starts_with("::");
                if !label || declared.contains(&span) {
                    index.uses.push((name, span));
                }
            }
            index.files.push(file);
        }
        for (i, d) in index.decls.iter().enumerate() {
            index.by_name.entry(d.name.clone()).or_default().push(i);
        }
        index
    }

    fn add(&mut self, name: &ast::Ident, what: What, span: Span, scope: Option<Span>) {
        self.decls.push(Decl {
            name: name.name.clone(),
            what,
            at: name.span,
            span,
            scope,
            value: None,
        });
    }

    fn item(&mut self, item: &ast::Item) {
        match item {
            ast::Item::Let(l) => {
                self.add(&l.name, What::Let, l.span, None);
                self.decls.last_mut().expect("just added").value = Some(l.value.span);
            }
            ast::Item::Fn(f) => {
                self.add(&f.name, What::Fn, f.span, None);
                for p in &f.params {
                    self.add(&p.name, What::Param, p.name.span, Some(f.span));
                }
                for l in &f.body.lets {
                    self.add(&l.name, What::Let, l.span, Some(f.span));
                    self.decls.last_mut().expect("just added").value = Some(l.value.span);
                }
            }
            ast::Item::Material { name, span, .. } => self.add(name, What::Material, *span, None),
            ast::Item::Scene { stmts, span } => self.stmts(stmts, *span),
            _ => {}
        }
    }

    fn stmts(&mut self, stmts: &[ast::Stmt], scope: Span) {
        for s in stmts {
            match s {
                ast::Stmt::Let(l) => {
                    self.add(&l.name, What::Let, l.span, Some(scope));
                    self.decls.last_mut().expect("just added").value = Some(l.value.span);
                }
                ast::Stmt::For {
                    var, body, span, ..
                } => {
                    self.add(var, What::Loop, var.span, Some(*span));
                    self.stmts(body, *span);
                }
                _ => {}
            }
        }
    }

    /// The declaration the name at `at` refers to: the innermost scoped one around it, else
    /// an item of its own file, else an item of another file (an import).
    pub fn resolve(&self, name: &str, at: Span) -> Option<&Decl> {
        let within = |s: &Span| s.file == at.file && s.start <= at.start && at.end <= s.end;
        let named = || {
            self.by_name
                .get(name)
                .into_iter()
                .flatten()
                .filter_map(|&i| self.decls.get(i))
        };
        let scoped = named()
            .filter(|d| d.scope.as_ref().is_some_and(within))
            .min_by_key(|d| d.scope.map_or(u32::MAX, |s| s.end - s.start));
        scoped
            .or_else(|| named().find(|d| d.scope.is_none() && d.at.file == at.file))
            .or_else(|| named().find(|d| d.scope.is_none()))
    }

    /// The identifier token covering byte `offset` of `file`.
    pub fn use_at(&self, file: FileId, offset: usize) -> Option<&(String, Span)> {
        self.uses.iter().find(|(_, s)| {
            s.file == file && (s.start as usize) <= offset && offset <= (s.end as usize)
        })
    }

    /// Every identifier that refers to `decl` (its own name included).
    pub fn references<'a>(&'a self, decl: &'a Decl) -> impl Iterator<Item = Span> + 'a {
        self.uses
            .iter()
            .filter(move |(name, _)| *name == decl.name)
            .filter(move |(name, span)| {
                *span == decl.at || self.resolve(name, *span).is_some_and(|d| d.at == decl.at)
            })
            .map(|(_, s)| *s)
    }
}
