//! The parser: tokens to [`ast::File`] (chumsky), with error recovery so that one run reports
//! every syntax error.
//!
//! Each parser function names the rule of `grammar/sdf.ebnf` it implements.

use super::ast::*;
use super::errors::{is_keyword, syntax_error};
use super::lexer::Token;
use crate::diagnostics::Diagnostic;
use crate::span::{FileId, Span};
use chumsky::{input::ValueInput, prelude::*};

type Extra<'t> = extra::Err<Rich<'t, Token, SimpleSpan>>;

/// The token streams the parsers read.
trait Tokens<'t>: ValueInput<'t, Token = Token, Span = SimpleSpan> {}

impl<'t, T: ValueInput<'t, Token = Token, Span = SimpleSpan>> Tokens<'t> for T {}

/// A parser of `O` from the tokens `I` that a rule may clone into several places.
trait Rule<'t, I: Tokens<'t>, O>: Parser<'t, I, O, Extra<'t>> + Clone + 't {}

impl<'t, I: Tokens<'t>, O, P: Parser<'t, I, O, Extra<'t>> + Clone + 't> Rule<'t, I, O> for P {}

/// Parses a token stream into a file. Always returns a tree (possibly with error nodes) and
/// the syntax errors found.
pub fn parse(file: FileId, tokens: &[(Token, Span)], eof: usize) -> (File, Vec<Diagnostic>) {
    // The tokens borrowed, not cloned: a copy of a 5 MB file's tokens, their names with them,
    // was 90 MB of `sdfc fmt`'s peak.
    let simple: Vec<(&Token, SimpleSpan)> = tokens
        .iter()
        .map(|(t, s)| (t, SimpleSpan::from(s.range())))
        .collect();
    let input = simple
        .as_slice()
        .map(SimpleSpan::from(eof..eof), |(t, s)| (*t, s));
    let (out, errors) = file_parser(file).parse(input).into_output_errors();
    // The materials this file declares, for "did you mean `@ red`?".
    let materials: Vec<&str> = tokens
        .windows(2)
        .filter_map(|w| match (&w[0].0, &w[1].0) {
            (Token::Material, Token::Ident(name)) => Some(name.as_str()),
            _ => None,
        })
        .collect();
    let mut diags: Vec<Diagnostic> = Vec::new();
    // After a keyword used as a name, the rest of its statement only echoes that mistake.
    let mut echo_until = None;
    for e in errors {
        let start = e.span().start;
        if echo_until.is_some_and(|end| start < end) {
            continue;
        }
        let keyword = matches!(e.found(), Some(t) if is_keyword(t))
            && e.expected()
                .any(|p| matches!(p, chumsky::error::RichPattern::Label(l) if *l == "name"));
        if keyword {
            echo_until = tokens
                .iter()
                .find(|(t, s)| s.start as usize > start && matches!(t, Token::Semi | Token::RBrace))
                .map(|(_, s)| s.end as usize);
        }
        diags.push(syntax_error(file, e, tokens, &materials));
    }
    (out.unwrap_or(File { items: Vec::new() }), diags)
}

fn sp(file: FileId, s: SimpleSpan) -> Span {
    Span::new(file, s.into_range())
}

/// `ident`
fn ident<'t, I: Tokens<'t>>(file: FileId) -> impl Rule<'t, I, Ident> {
    select! { Token::Ident(name) => name }
        .map_with(move |name, e| Ident {
            name,
            span: sp(file, e.span()),
        })
        .labelled("name")
}

/// `type = ident | "[" type "]"`: a list type is kept as one name, `[shape]`, spanning the
/// brackets.
fn type_name<'t, I: Tokens<'t>>(file: FileId) -> impl Rule<'t, I, Ident> {
    recursive(move |ty| {
        ident(file).or(ty
            .delimited_by(just(Token::LBracket), just(Token::RBracket))
            .map_with(move |inner: Ident, e| Ident {
                name: format!("[{}]", inner.name),
                span: sp(file, e.span()),
            }))
    })
    .labelled("type")
}

/// A boxed parser of expressions: the precedence levels are boxed, each over the one below.
type BoxedExpr<'t, I> = chumsky::Boxed<'t, 't, I, Expr, Extra<'t>>;

/// An expression of `kind` spanning the tokens of `s`.
fn mk(file: FileId, kind: ExprKind, s: SimpleSpan) -> Expr {
    Expr {
        kind,
        span: sp(file, s),
    }
}

/// `expr` with all its precedence levels, and `body`.
fn expr_parser<'t, I: Tokens<'t>>(file: FileId) -> impl Rule<'t, I, Expr> {
    recursive(move |expr| {
        let body = body(file, expr.clone()).boxed();
        let args = args(file, expr.clone());
        let atom = atom(file, expr.clone(), body, args.clone());
        let logic = logic(file, unary(file, postfix(file, atom, expr, args)));
        // `expr = logic { "@" ident }`
        logic
            .foldl_with(
                just(Token::At).ignore_then(ident(file)).repeated(),
                move |shape, mat, e| mk(file, ExprKind::Material(Box::new(shape), mat), e.span()),
            )
            .labelled("expression")
    })
}

/// `let_stmt = let`, `let = "let" ident [":" type] "=" expr ";"`: a local of a body, or an
/// item.
fn let_stmt<'t, I: Tokens<'t>>(
    file: FileId,
    expr: impl Rule<'t, I, Expr>,
) -> impl Rule<'t, I, Let> {
    just(Token::Let)
        .ignore_then(ident(file))
        .then(just(Token::Colon).ignore_then(type_name(file)).or_not())
        .then_ignore(just(Token::Eq))
        .then(expr)
        .then_ignore(just(Token::Semi))
        .map_with(move |((name, ty), value), e| Let {
            name,
            ty,
            value,
            param: None,
            span: sp(file, e.span()),
        })
}

/// `body = "{" { let_stmt } expr "}"`
fn body<'t, I: Tokens<'t>>(file: FileId, expr: impl Rule<'t, I, Expr>) -> impl Rule<'t, I, Body> {
    let_stmt(file, expr.clone())
        .repeated()
        .collect::<Vec<_>>()
        .then(expr)
        .delimited_by(just(Token::LBrace), just(Token::RBrace))
        .map_with(move |(lets, value), e| Body {
            lets,
            value: Box::new(value),
            span: sp(file, e.span()),
        })
}

/// `args = "(" [ arg { "," arg } [","] ] ")"`, `arg = [ident ":"] expr`
fn args<'t, I: Tokens<'t>>(
    file: FileId,
    expr: impl Rule<'t, I, Expr>,
) -> impl Rule<'t, I, Vec<Arg>> {
    let arg = ident(file)
        .then_ignore(just(Token::Colon))
        .or_not()
        .then(expr)
        .map(|(name, value)| Arg { name, value });
    arg.separated_by(just(Token::Comma))
        .allow_trailing()
        .collect::<Vec<_>>()
        .delimited_by(just(Token::LParen), just(Token::RParen))
        .labelled("arguments")
        .boxed()
}

/// `atom = literal | field_shape | call | ident | tuple | list | if`
fn atom<'t, I: Tokens<'t>>(
    file: FileId,
    expr: impl Rule<'t, I, Expr>,
    body: impl Rule<'t, I, Body>,
    args: impl Rule<'t, I, Vec<Arg>>,
) -> BoxedExpr<'t, I> {
    // `call = ident args`
    let call = ident(file)
        .then(args.clone())
        .map_with(move |(callee, args), e| mk(file, ExprKind::Call { callee, args }, e.span()));
    let var = ident(file).map(|id| {
        let span = id.span;
        Expr {
            kind: ExprKind::Var(id),
            span,
        }
    });
    choice((
        literal(file),
        field_shape(file, body.clone(), args),
        call,
        var,
        tuple(file, expr.clone()),
        list(file, expr.clone(), body.clone()),
        if_expr(file, expr, body),
    ))
    .labelled("expression")
    .boxed()
}

/// `literal = INT | FLOAT | ANGLE | COLOUR | BOOL | STRING`
fn literal<'t, I: Tokens<'t>>(file: FileId) -> impl Rule<'t, I, Expr> {
    select! {
        Token::Int(v) => ExprKind::Int(v),
        Token::Float(v) => ExprKind::Float(v),
        Token::Angle(v) => ExprKind::Angle(v),
        Token::Colour(c) => ExprKind::Colour(c),
        Token::Bool(v) => ExprKind::Bool(v),
        Token::Str(v) => ExprKind::Str(v),
    }
    .map_with(move |k, e| mk(file, k, e.span()))
}

/// `tuple = "(" expr { "," expr } [","] ")"`: one element without comma is parentheses.
fn tuple<'t, I: Tokens<'t>>(file: FileId, expr: impl Rule<'t, I, Expr>) -> impl Rule<'t, I, Expr> {
    expr.separated_by(just(Token::Comma))
        .at_least(1)
        .collect::<Vec<_>>()
        .then(just(Token::Comma).or_not())
        .delimited_by(just(Token::LParen), just(Token::RParen))
        .map_with(move |(mut items, trailing), e| {
            if items.len() == 1 && trailing.is_none() {
                let mut inner = items.pop().expect("one item");
                inner.span = sp(file, e.span());
                inner
            } else {
                mk(file, ExprKind::Tuple(items), e.span())
            }
        })
        .recover_with(via_parser(nested_delimiters(
            Token::LParen,
            Token::RParen,
            [(Token::LBrace, Token::RBrace)],
            move |s| mk(file, ExprKind::Error, s),
        )))
}

/// `if = "if" expr body "else" (body | if)`
fn if_expr<'t, I: Tokens<'t>>(
    file: FileId,
    expr: impl Rule<'t, I, Expr>,
    body: impl Rule<'t, I, Body>,
) -> impl Rule<'t, I, Expr> {
    recursive(|if_expr| {
        just(Token::If)
            .ignore_then(expr)
            .then(body.clone())
            .then_ignore(just(Token::Else))
            .then(body.or(if_expr.map(move |e: Expr| {
                let span = e.span;
                Body {
                    lets: Vec::new(),
                    value: Box::new(e),
                    span,
                }
            })))
            .map_with(move |((cond, then), otherwise), e| {
                mk(
                    file,
                    ExprKind::If {
                        cond: Box::new(cond),
                        then,
                        otherwise,
                    },
                    e.span(),
                )
            })
    })
}

/// `list = "[" "for" ident "in" expr ".." expr [ "if" expr ] body "]"
///      | "[" [ expr { "," expr } [ "," ] ] "]"`
fn list<'t, I: Tokens<'t>>(
    file: FileId,
    expr: impl Rule<'t, I, Expr>,
    body: impl Rule<'t, I, Body>,
) -> impl Rule<'t, I, Expr> {
    let comprehension = for_range(file, expr.clone())
        .then(just(Token::If).ignore_then(expr.clone()).or_not())
        .then(body)
        .map(|((((var, from), to), cond), body)| (var, from, to, cond, body));
    comprehension
        .map(Ok)
        .or(expr
            .separated_by(just(Token::Comma))
            .allow_trailing()
            .collect::<Vec<_>>()
            .map(Err))
        .delimited_by(just(Token::LBracket), just(Token::RBracket))
        .map_with(move |list, e| {
            let kind = match list {
                Ok((var, from, to, cond, body)) => ExprKind::Comprehension {
                    var,
                    from: Box::new(from),
                    to: Box::new(to),
                    cond: cond.map(Box::new),
                    body,
                },
                Err(items) => ExprKind::List(items),
            };
            mk(file, kind, e.span())
        })
        .recover_with(via_parser(nested_delimiters(
            Token::LBracket,
            Token::RBracket,
            [
                (Token::LParen, Token::RParen),
                (Token::LBrace, Token::RBrace),
            ],
            move |s| mk(file, ExprKind::Error, s),
        )))
}

/// The head of a loop, `"for" ident "in" expr ".." expr`, shared by `list` and `for`: the
/// variable and the range's ends.
fn for_range<'t, I: Tokens<'t>>(
    file: FileId,
    expr: impl Rule<'t, I, Expr>,
) -> impl Rule<'t, I, ((Ident, Expr), Expr)> {
    just(Token::For)
        .ignore_then(ident(file))
        .then_ignore(just(Token::In))
        .then(expr.clone())
        .then_ignore(just(Token::DotDot))
        .then(expr)
}

/// `field_shape = ident [ args ] body`, the name being `field` or `profile` (names
/// elsewhere).
fn field_shape<'t, I: Tokens<'t>>(
    file: FileId,
    body: impl Rule<'t, I, Body>,
    args: impl Rule<'t, I, Vec<Arg>>,
) -> impl Rule<'t, I, Expr> {
    select! {
        Token::Ident(name) if name == "field" => false,
        Token::Ident(name) if name == "profile" => true,
    }
    .then(args.or_not())
    .then(body)
    .map_with(move |((plane, args), body), e| {
        mk(
            file,
            ExprKind::FieldBlock {
                args: args.unwrap_or_default(),
                body,
                plane,
            },
            e.span(),
        )
    })
}

/// `postfix = atom { "." ident [args] | "[" expr "]" }`
fn postfix<'t, I: Tokens<'t>>(
    file: FileId,
    atom: BoxedExpr<'t, I>,
    expr: impl Rule<'t, I, Expr>,
    args: impl Rule<'t, I, Vec<Arg>>,
) -> BoxedExpr<'t, I> {
    let suffix = just(Token::Dot)
        .ignore_then(ident(file))
        .then(args.or_not())
        .map(Ok)
        .or(expr
            .delimited_by(just(Token::LBracket), just(Token::RBracket))
            .map(Err));
    atom.foldl_with(suffix.repeated(), move |receiver, suffix, e| {
        let kind = match suffix {
            Ok((name, Some(args))) => ExprKind::Method {
                receiver: Box::new(receiver),
                name,
                args,
            },
            Ok((name, None)) => ExprKind::Field(Box::new(receiver), name),
            Err(index) => ExprKind::Index(Box::new(receiver), Box::new(index)),
        };
        mk(file, kind, e.span())
    })
    .boxed()
}

/// `unary = { "-" | "!" } postfix`
fn unary<'t, I: Tokens<'t>>(file: FileId, postfix: BoxedExpr<'t, I>) -> BoxedExpr<'t, I> {
    choice((
        just(Token::Minus).to(UnOp::Neg),
        just(Token::Bang).to(UnOp::Not),
    ))
    .map_with(move |op, e| (op, sp(file, e.span())))
    .repeated()
    .foldr(postfix, move |(op, op_span), rhs: Expr| {
        let span = op_span.join(rhs.span);
        Expr {
            kind: ExprKind::Unary(op, Box::new(rhs)),
            span,
        }
    })
    .boxed()
}

/// `logic = or`, `or = and { "||" and }`, `and = compare { "&&" compare }`,
/// `compare = sum { ( "==" | "!=" | "<=" | ">=" | "<" | ">" ) sum }`,
/// `sum = product { ( "+" | "-" ) product }`, `product = unary { ( "*" | "/" | "%" ) unary }`
fn logic<'t, I: Tokens<'t>>(file: FileId, unary: BoxedExpr<'t, I>) -> BoxedExpr<'t, I> {
    // The levels from the tightest: product, sum, compare, and, or.
    let levels = [
        vec![
            (Token::Star, BinOp::Mul),
            (Token::Slash, BinOp::Div),
            (Token::Percent, BinOp::Rem),
        ],
        vec![(Token::Plus, BinOp::Add), (Token::Minus, BinOp::Sub)],
        vec![
            (Token::EqEq, BinOp::Eq),
            (Token::Ne, BinOp::Ne),
            (Token::Le, BinOp::Le),
            (Token::Ge, BinOp::Ge),
            (Token::Lt, BinOp::Lt),
            (Token::Gt, BinOp::Gt),
        ],
        vec![(Token::AndAnd, BinOp::And)],
        vec![(Token::OrOr, BinOp::Or)],
    ];
    levels
        .into_iter()
        .fold(unary, |lower, ops| binary(file, lower, ops))
}

/// One level of binary operators, left-associative over the level below.
fn binary<'t, I: Tokens<'t>>(
    file: FileId,
    lower: BoxedExpr<'t, I>,
    ops: Vec<(Token, BinOp)>,
) -> BoxedExpr<'t, I> {
    let op = choice(
        ops.into_iter()
            .map(|(t, o)| just(t).to(o))
            .collect::<Vec<_>>(),
    );
    lower
        .clone()
        .foldl_with(op.then(lower).repeated(), move |a, (op, b), e| {
            mk(
                file,
                ExprKind::Binary(op, Box::new(a), Box::new(b)),
                e.span(),
            )
        })
        .boxed()
}

/// `file = { item }`
fn file_parser<'t, I: Tokens<'t>>(file: FileId) -> impl Parser<'t, I, File, Extra<'t>> {
    let expr = expr_parser(file).boxed();
    let let_decl = let_stmt(file, expr.clone()).boxed();
    let fields = fields(file, expr.clone());
    let stmt = recursive(|stmt| statement(file, let_decl.clone(), expr.clone(), stmt));
    // A broken item is skipped up to the next item keyword, so the items after it are
    // still parsed and their errors reported.
    let item_start = [
        Token::Import,
        Token::Let,
        Token::Param,
        Token::Fn,
        Token::Material,
        Token::Camera,
        Token::Light,
        Token::Render,
        Token::Scene,
    ];
    let skip_item = any()
        .then(none_of(item_start).repeated())
        .map_with(move |_, e| Item::Error(sp(file, e.span())));
    let item = choice((
        import(file),
        let_decl.map(Item::Let),
        param_decl(file, expr.clone()).map(Item::Let),
        function(file, expr),
        material(file, fields.clone()),
        block(file, fields),
        scene(file, stmt),
    ))
    .labelled("item")
    .recover_with(via_parser(skip_item));

    item.repeated()
        .collect::<Vec<_>>()
        .then_ignore(end())
        .map(|items| File { items })
}

/// `import = "import" STRING ";"`
fn import<'t, I: Tokens<'t>>(file: FileId) -> impl Rule<'t, I, Item> {
    just(Token::Import)
        .ignore_then(select! { Token::Str(s) => s }.labelled("a file name in quotes"))
        .then_ignore(just(Token::Semi))
        .map_with(move |path, e| Item::Import {
            path,
            span: sp(file, e.span()),
        })
}

/// `parameter = "param" ident "=" expr ["in" (expr ".." expr [ident expr] | expr)] [expr] ";"`: the ident is `step`
fn param_decl<'t, I: Tokens<'t>>(
    file: FileId,
    expr: impl Rule<'t, I, Expr>,
) -> impl Rule<'t, I, Let> {
    let step = select! { Token::Ident(s) if s == "step" => () };
    just(Token::Param)
        .ignore_then(ident(file))
        .then_ignore(just(Token::Eq))
        .then(expr.clone())
        .then(
            just(Token::In)
                .ignore_then(expr.clone())
                .then(
                    just(Token::DotDot)
                        .ignore_then(expr.clone())
                        .then(step.ignore_then(expr.clone()).or_not())
                        .or_not(),
                )
                .or_not(),
        )
        .then(expr.or_not())
        .then_ignore(just(Token::Semi))
        .map_with(move |(((name, value), values), doc), e| {
            let (range, step, choices) = match values {
                Some((lo, Some((hi, step)))) => (Some((lo, hi)), step, None),
                Some((list, None)) => (None, None, Some(list)),
                None => (None, None, None),
            };
            Let {
                name,
                ty: None,
                value,
                param: Some(Box::new(ParamSpec {
                    range,
                    step,
                    choices,
                    doc,
                })),
                span: sp(file, e.span()),
            }
        })
        .boxed()
}

/// `fn = "fn" ident "(" params ")" "->" type body`, `params = [ param { "," param } [ "," ] ]`,
/// `param = ident ":" type ["=" expr]`; a broken body is skipped to its closing brace.
fn function<'t, I: Tokens<'t>>(
    file: FileId,
    expr: impl Rule<'t, I, Expr>,
) -> impl Rule<'t, I, Item> {
    let param = ident(file)
        .then_ignore(just(Token::Colon))
        .then(type_name(file))
        .then(just(Token::Eq).ignore_then(expr.clone()).or_not())
        .map(|((name, ty), default)| Param { name, ty, default });
    let body = body(file, expr).recover_with(via_parser(nested_delimiters(
        Token::LBrace,
        Token::RBrace,
        [(Token::LParen, Token::RParen)],
        move |s| Body {
            lets: Vec::new(),
            value: Box::new(Expr {
                kind: ExprKind::Error,
                span: sp(file, s),
            }),
            span: sp(file, s),
        },
    )));
    just(Token::Fn)
        .ignore_then(ident(file))
        .then(
            param
                .separated_by(just(Token::Comma))
                .allow_trailing()
                .collect::<Vec<_>>()
                .delimited_by(just(Token::LParen), just(Token::RParen)),
        )
        .then_ignore(just(Token::Arrow))
        .then(type_name(file))
        .then(body)
        .map_with(move |(((name, params), ret), body), e| {
            Item::Fn(FnDecl {
                name,
                params,
                ret,
                body,
                span: sp(file, e.span()),
            })
        })
}

/// `field = ident ":" expr`, `fields = "{" [field {"," field} [","]] "}"`
fn fields<'t, I: Tokens<'t>>(
    file: FileId,
    expr: impl Rule<'t, I, Expr>,
) -> impl Rule<'t, I, Vec<Field>> {
    ident(file)
        .then_ignore(just(Token::Colon))
        .then(expr)
        .map(|(name, value)| Field { name, value })
        .separated_by(just(Token::Comma))
        .allow_trailing()
        .collect::<Vec<_>>()
        .delimited_by(just(Token::LBrace), just(Token::RBrace))
        .recover_with(via_parser(nested_delimiters(
            Token::LBrace,
            Token::RBrace,
            [(Token::LParen, Token::RParen)],
            |_| Vec::new(),
        )))
        .boxed()
}

/// `material = "material" ident "=" ident fields [";"]`
fn material<'t, I: Tokens<'t>>(
    file: FileId,
    fields: impl Rule<'t, I, Vec<Field>>,
) -> impl Rule<'t, I, Item> {
    just(Token::Material)
        .ignore_then(ident(file))
        .then_ignore(just(Token::Eq))
        .then(ident(file))
        .then(fields)
        .then_ignore(just(Token::Semi).or_not())
        .map_with(move |((name, kind), fields), e| Item::Material {
            name,
            kind,
            fields,
            span: sp(file, e.span()),
        })
}

/// `block = ("camera" | "render" | "light" ident) fields [";"]`
fn block<'t, I: Tokens<'t>>(
    file: FileId,
    fields: impl Rule<'t, I, Vec<Field>>,
) -> impl Rule<'t, I, Item> {
    let keyword = move |t: Token, name: &'static str| {
        just(t).map_with(move |_, e| Ident {
            name: name.to_string(),
            span: sp(file, e.span()),
        })
    };
    choice((
        keyword(Token::Camera, "camera").then(empty().to(None)),
        keyword(Token::Render, "render").then(empty().to(None)),
        keyword(Token::Light, "light").then(ident(file).map(Some)),
    ))
    .then(fields)
    .then_ignore(just(Token::Semi).or_not())
    .map_with(move |((keyword, kind), fields), e| {
        Item::Block(Block {
            keyword,
            kind,
            fields,
            span: sp(file, e.span()),
        })
    })
}

/// `stmt = let | for | expr ";"`, `for = "for" ident "in" expr ".." expr "{" { stmt } "}"`, the
/// statements of a `for` read by `stmt`; a broken statement is skipped to its `;` (or to the
/// `}` closing the block).
fn statement<'t, I: Tokens<'t>>(
    file: FileId,
    let_decl: impl Rule<'t, I, Let>,
    expr: impl Rule<'t, I, Expr>,
    stmt: impl Rule<'t, I, Stmt>,
) -> impl Rule<'t, I, Stmt> {
    let for_stmt = for_range(file, expr.clone())
        .then(
            stmt.repeated()
                .collect::<Vec<_>>()
                .delimited_by(just(Token::LBrace), just(Token::RBrace)),
        )
        .map_with(move |(((var, from), to), body), e| Stmt::For {
            var,
            from,
            to,
            body,
            span: sp(file, e.span()),
        });
    let skip_stmt = none_of([Token::RBrace])
        .then(none_of([Token::Semi, Token::RBrace]).repeated())
        .then(just(Token::Semi).or_not())
        .map_with(move |_, e| Stmt::Error(sp(file, e.span())));
    choice((
        let_decl.map(Stmt::Let),
        for_stmt,
        expr.then_ignore(just(Token::Semi)).map(Stmt::Object),
    ))
    .recover_with(via_parser(skip_stmt))
    .boxed()
}

/// `scene = "scene" "{" { stmt } "}" [";"]`
fn scene<'t, I: Tokens<'t>>(file: FileId, stmt: impl Rule<'t, I, Stmt>) -> impl Rule<'t, I, Item> {
    just(Token::Scene)
        .ignore_then(
            stmt.repeated()
                .collect::<Vec<_>>()
                .delimited_by(just(Token::LBrace), just(Token::RBrace)),
        )
        .then_ignore(just(Token::Semi).or_not())
        .map_with(move |stmts, e| Item::Scene {
            stmts,
            span: sp(file, e.span()),
        })
}
