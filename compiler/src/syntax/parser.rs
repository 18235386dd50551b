//! The parser: tokens to [`ast::File`] (chumsky), with error recovery so that one run reports
//! every syntax error.
//!
//! Each parser function names the rule of `grammar/sdf.ebnf` it implements.

use super::ast::*;
use super::lexer::Token;
use crate::diagnostics::Diagnostic;
use crate::span::{FileId, Span};
use chumsky::{input::ValueInput, prelude::*};

type Extra<'t> = extra::Err<Rich<'t, Token, SimpleSpan>>;

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

/// The keywords: reserved, they cannot be names.
fn is_keyword(t: &Token) -> bool {
    matches!(
        t,
        Token::Import
            | Token::Let
            | Token::Fn
            | Token::Material
            | Token::Camera
            | Token::Light
            | Token::Render
            | Token::Scene
            | Token::If
            | Token::Else
            | Token::For
            | Token::In
    )
}

fn syntax_error(
    file: FileId,
    e: Rich<'_, Token, SimpleSpan>,
    tokens: &[(Token, Span)],
    materials: &[&str],
) -> Diagnostic {
    use chumsky::error::RichPattern;
    let span = Span::new(file, e.span().into_range());
    let found = match e.found() {
        Some(t) => t.to_string(),
        None => "end of file".to_string(),
    };
    let mut expected: Vec<String> = e
        .expected()
        .filter_map(|p| match p {
            RichPattern::Token(t) => Some(t.to_string()),
            RichPattern::Label(l) => Some(l.to_string()),
            RichPattern::EndOfInput => Some("end of file".to_string()),
            _ => None,
        })
        .collect();
    expected.sort();
    expected.dedup();
    if let chumsky::error::RichReason::Custom(msg) = e.reason() {
        return Diagnostic::error("E0100", msg.to_string(), span);
    }
    if let Some(t) = e.found().filter(|t| is_keyword(t)) {
        if expected.iter().any(|x| x == "name") {
            return Diagnostic::error(
                "E0100",
                format!("{found} is a keyword, not a name"),
                span,
            )
            .with_label("a keyword cannot be used as a name")
            .with_note("the keywords are import, let, fn, material, camera, light, render, scene, if, else, for and in")
            .with_help(format!("choose another name, such as `{}1`", t.to_string().trim_matches('`')));
        }
    }
    // `.5`: a number written without its leading zero (the digits as written: `.05` is the
    // integer 5 in two digits).
    let leading_dot = match (e.found(), tokens.iter().find(|(_, s)| s.start >= span.end)) {
        (Some(Token::Dot), Some((Token::Int(n), s))) if s.start == span.end => {
            let digits = format!("{n:0width$}", width = s.range().len());
            Some(format!("write `0.{digits}`: a number starts with a digit"))
        }
        _ => None,
    };
    // A missing `;`, `,` or closing delimiter is reported just after the previous token, where
    // it belongs, rather than at the next token.
    let closers: Vec<&str> = ["`;`", "`,`", "`)`", "`}`"]
        .into_iter()
        .filter(|c| expected.iter().any(|x| x == c))
        .collect();
    if !closers.is_empty() && e.found().is_some() {
        if let Some(prev) = tokens.iter().rev().find(|(_, s)| s.end <= span.start) {
            let at = Span {
                file,
                start: prev.1.end,
                end: prev.1.end,
            };
            let list = closers.join(" or ");
            let mut d = Diagnostic::error("E0101", format!("expected {list}, found {found}"), at)
                .with_label("something is missing here")
                .with_secondary(span, format!("found {found}"));
            let after_call = matches!(prev.0, Token::RParen);
            if let Some(help) = &leading_dot {
                d = d.with_help(help.clone());
            }
            match e.found() {
                Some(Token::Ident(u)) if u == "deg" || u == "rad" => {
                    d = d.with_help("write an angle's unit right after the number, as in `90deg`");
                }
                // `sphere(1) red;`: the `@` before a material is missing.
                Some(Token::Ident(name))
                    if closers.contains(&"`;`")
                        && expected.iter().any(|x| x == "`@`")
                        && (materials.contains(&name.as_str()) || after_call) =>
                {
                    d = d.with_help(format!(
                        "did you mean `@ {name}`? A shape is painted with `shape @ material`"
                    ));
                    if materials.contains(&name.as_str()) {
                        d = d.with_note(format!("`{name}` is a material declared in this file"));
                    }
                }
                _ => {}
            }
            return d;
        }
    }
    let mut d = Diagnostic::error("E0100", format!("unexpected {found}"), span)
        .with_label(format!("unexpected {found}"));
    if let Some(help) = leading_dot {
        d = d.with_help(help);
    }
    if matches!(e.found(), Some(Token::For)) && !expected.iter().any(|x| x == "`for`") {
        d = d.with_help(
            "a `for` statement belongs in the `scene` block; in an expression, such as a function's body, build a list with `[for i in 0..n { ... }]` and combine it with `union(...)`",
        );
    }
    if !expected.is_empty() {
        let list = if expected.len() > 8 {
            format!("{}, …", expected[..8].join(", "))
        } else {
            expected.join(", ")
        };
        d = d.with_note(format!("expected {list}"));
    }
    d
}

fn sp(file: FileId, s: SimpleSpan) -> Span {
    Span::new(file, s.into_range())
}

/// `ident`
fn ident<'t, I>(file: FileId) -> impl Parser<'t, I, Ident, Extra<'t>> + Clone
where
    I: ValueInput<'t, Token = Token, Span = SimpleSpan>,
{
    select! { Token::Ident(name) => name }
        .map_with(move |name, e| Ident {
            name,
            span: sp(file, e.span()),
        })
        .labelled("name")
}

/// `type = ident | "[" type "]"`: a list type is kept as one name, `[shape]`, spanning the
/// brackets.
fn type_name<'t, I>(file: FileId) -> impl Parser<'t, I, Ident, Extra<'t>> + Clone
where
    I: ValueInput<'t, Token = Token, Span = SimpleSpan>,
{
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

/// `expr` with all its precedence levels, and `body`.
fn expr_parser<'t, I>(file: FileId) -> impl Parser<'t, I, Expr, Extra<'t>> + Clone
where
    I: ValueInput<'t, Token = Token, Span = SimpleSpan>,
{
    recursive(move |expr| {
        let mk = move |kind: ExprKind, s: SimpleSpan| Expr {
            kind,
            span: sp(file, s),
        };

        // `let_stmt = "let" ident [":" ident] "=" expr ";"`
        let local_let = just(Token::Let)
            .ignore_then(ident(file))
            .then(just(Token::Colon).ignore_then(type_name(file)).or_not())
            .then_ignore(just(Token::Eq))
            .then(expr.clone())
            .then_ignore(just(Token::Semi))
            .map_with(move |((name, ty), value), e| Let {
                name,
                ty,
                value,
                param: None,
                span: sp(file, e.span()),
            });

        // `body = "{" { let_stmt } expr "}"`
        let body = local_let
            .repeated()
            .collect::<Vec<_>>()
            .then(expr.clone())
            .delimited_by(just(Token::LBrace), just(Token::RBrace))
            .map_with(move |(lets, value), e| Body {
                lets,
                value: Box::new(value),
                span: sp(file, e.span()),
            })
            .boxed();

        // `args = "(" [ arg { "," arg } [","] ] ")"`, `arg = [ident ":"] expr`
        let arg = ident(file)
            .then_ignore(just(Token::Colon))
            .or_not()
            .then(expr.clone())
            .map(|(name, value)| Arg { name, value });
        let args = arg
            .separated_by(just(Token::Comma))
            .allow_trailing()
            .collect::<Vec<_>>()
            .delimited_by(just(Token::LParen), just(Token::RParen))
            .labelled("arguments")
            .boxed();

        let literal = select! {
            Token::Int(v) => ExprKind::Int(v),
            Token::Float(v) => ExprKind::Float(v),
            Token::Angle(v) => ExprKind::Angle(v),
            Token::Colour(c) => ExprKind::Colour(c),
            Token::Bool(v) => ExprKind::Bool(v),
            Token::Str(v) => ExprKind::Str(v),
        }
        .map_with(move |k, e| mk(k, e.span()));

        // `call = ident args`
        let call = ident(file)
            .then(args.clone())
            .map_with(move |(callee, args), e| mk(ExprKind::Call { callee, args }, e.span()));

        let var = ident(file).map(|id| {
            let span = id.span;
            Expr {
                kind: ExprKind::Var(id),
                span,
            }
        });

        // `tuple = "(" expr { "," expr } [","] ")"`: one element without comma is parentheses.
        let tuple = expr
            .clone()
            .separated_by(just(Token::Comma))
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
                    mk(ExprKind::Tuple(items), e.span())
                }
            })
            .recover_with(via_parser(nested_delimiters(
                Token::LParen,
                Token::RParen,
                [(Token::LBrace, Token::RBrace)],
                move |s| mk(ExprKind::Error, s),
            )));

        // `if = "if" expr body "else" (body | if)`
        let if_expr = recursive(|if_expr| {
            just(Token::If)
                .ignore_then(expr.clone())
                .then(body.clone())
                .then_ignore(just(Token::Else))
                .then(body.clone().or(if_expr.map(move |e: Expr| {
                    let span = e.span;
                    Body {
                        lets: Vec::new(),
                        value: Box::new(e),
                        span,
                    }
                })))
                .map_with(move |((cond, then), otherwise), e| {
                    mk(
                        ExprKind::If {
                            cond: Box::new(cond),
                            then,
                            otherwise,
                        },
                        e.span(),
                    )
                })
        });

        // `list = "[" "for" ident "in" expr ".." expr [ "if" expr ] body "]"
        //      | "[" [ expr { "," expr } [ "," ] ] "]"`
        let comprehension = just(Token::For)
            .ignore_then(ident(file))
            .then_ignore(just(Token::In))
            .then(expr.clone())
            .then_ignore(just(Token::DotDot))
            .then(expr.clone())
            .then(just(Token::If).ignore_then(expr.clone()).or_not())
            .then(body.clone())
            .map(|((((var, from), to), cond), body)| (var, from, to, cond, body));
        let list = comprehension
            .map(Ok)
            .or(expr
                .clone()
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
                mk(kind, e.span())
            })
            .recover_with(via_parser(nested_delimiters(
                Token::LBracket,
                Token::RBracket,
                [
                    (Token::LParen, Token::RParen),
                    (Token::LBrace, Token::RBrace),
                ],
                move |s| mk(ExprKind::Error, s),
            )));

        // `field_shape = ident [ args ] body`, the name being `field` or `profile` (names
        // elsewhere).
        let field = select! {
            Token::Ident(name) if name == "field" => false,
            Token::Ident(name) if name == "profile" => true,
        }
        .then(args.clone().or_not())
        .then(body.clone())
        .map_with(move |((plane, args), body), e| {
            mk(
                ExprKind::FieldBlock {
                    args: args.unwrap_or_default(),
                    body,
                    plane,
                },
                e.span(),
            )
        });

        let atom = choice((literal, field, call, var, tuple, list, if_expr))
            .labelled("expression")
            .boxed();

        // `postfix = atom { "." ident [args] | "[" expr "]" }`
        let suffix = just(Token::Dot)
            .ignore_then(ident(file))
            .then(args.clone().or_not())
            .map(Ok)
            .or(expr
                .clone()
                .delimited_by(just(Token::LBracket), just(Token::RBracket))
                .map(Err));
        let postfix = atom
            .foldl_with(suffix.repeated(), move |receiver, suffix, e| {
                let kind = match suffix {
                    Ok((name, Some(args))) => ExprKind::Method {
                        receiver: Box::new(receiver),
                        name,
                        args,
                    },
                    Ok((name, None)) => ExprKind::Field(Box::new(receiver), name),
                    Err(index) => ExprKind::Index(Box::new(receiver), Box::new(index)),
                };
                mk(kind, e.span())
            })
            .boxed();

        // `unary = { "-" | "!" } postfix`
        let unary = choice((
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
        .boxed();

        let binary = move |lower: chumsky::Boxed<'t, 't, I, Expr, Extra<'t>>,
                           ops: Vec<(Token, BinOp)>| {
            let op = choice(
                ops.into_iter()
                    .map(|(t, o)| just(t).to(o))
                    .collect::<Vec<_>>(),
            );
            lower
                .clone()
                .foldl_with(op.then(lower).repeated(), move |a, (op, b), e| {
                    mk(ExprKind::Binary(op, Box::new(a), Box::new(b)), e.span())
                })
                .boxed()
        };
        let product = binary(
            unary,
            vec![
                (Token::Star, BinOp::Mul),
                (Token::Slash, BinOp::Div),
                (Token::Percent, BinOp::Rem),
            ],
        );
        let sum = binary(
            product,
            vec![(Token::Plus, BinOp::Add), (Token::Minus, BinOp::Sub)],
        );
        let compare = binary(
            sum,
            vec![
                (Token::EqEq, BinOp::Eq),
                (Token::Ne, BinOp::Ne),
                (Token::Le, BinOp::Le),
                (Token::Ge, BinOp::Ge),
                (Token::Lt, BinOp::Lt),
                (Token::Gt, BinOp::Gt),
            ],
        );
        let and = binary(compare, vec![(Token::AndAnd, BinOp::And)]);
        let or = binary(and, vec![(Token::OrOr, BinOp::Or)]);

        // `expr = logic { "@" ident }`
        or.foldl_with(
            just(Token::At).ignore_then(ident(file)).repeated(),
            move |shape, mat, e| mk(ExprKind::Material(Box::new(shape), mat), e.span()),
        )
        .labelled("expression")
    })
}

/// `file = { item }`
fn file_parser<'t, I>(file: FileId) -> impl Parser<'t, I, File, Extra<'t>>
where
    I: ValueInput<'t, Token = Token, Span = SimpleSpan>,
{
    let expr = expr_parser(file).boxed();

    // `let = "let" ident [":" ident] "=" expr ";"`
    let let_decl = just(Token::Let)
        .ignore_then(ident(file))
        .then(just(Token::Colon).ignore_then(type_name(file)).or_not())
        .then_ignore(just(Token::Eq))
        .then(expr.clone())
        .then_ignore(just(Token::Semi))
        .map_with(move |((name, ty), value), e| Let {
            name,
            ty,
            value,
            param: None,
            span: sp(file, e.span()),
        })
        .boxed();

    // `parameter = "param" ident "=" expr ["in" (expr ".." expr [ident expr] | expr)] [expr] ";"`: the ident is `step`
    let step = select! { Token::Ident(s) if s == "step" => () };
    let param_decl = just(Token::Param)
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
        .then(expr.clone().or_not())
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
        .boxed();

    // `field = ident ":" expr`, `fields = "{" [field {"," field} [","]] "}"`
    let fields = ident(file)
        .then_ignore(just(Token::Colon))
        .then(expr.clone())
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
        .boxed();

    let import = just(Token::Import)
        .ignore_then(select! { Token::Str(s) => s }.labelled("a file name in quotes"))
        .then_ignore(just(Token::Semi))
        .map_with(move |path, e| Item::Import {
            path,
            span: sp(file, e.span()),
        });

    // `param = ident ":" type ["=" expr]`
    let param = ident(file)
        .then_ignore(just(Token::Colon))
        .then(type_name(file))
        .then(just(Token::Eq).ignore_then(expr.clone()).or_not())
        .map(|((name, ty), default)| Param { name, ty, default });

    // `fn = "fn" ident "(" params ")" "->" type body`
    let local_let = let_decl.clone();
    let body = local_let
        .repeated()
        .collect::<Vec<_>>()
        .then(expr.clone())
        .delimited_by(just(Token::LBrace), just(Token::RBrace))
        .map_with(move |(lets, value), e| Body {
            lets,
            value: Box::new(value),
            span: sp(file, e.span()),
        })
        .recover_with(via_parser(nested_delimiters(
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
    let function = just(Token::Fn)
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
        });

    // `material = "material" ident "=" ident fields [";"]`
    let material = just(Token::Material)
        .ignore_then(ident(file))
        .then_ignore(just(Token::Eq))
        .then(ident(file))
        .then(fields.clone())
        .then_ignore(just(Token::Semi).or_not())
        .map_with(move |((name, kind), fields), e| Item::Material {
            name,
            kind,
            fields,
            span: sp(file, e.span()),
        });

    // `block = ("camera" | "render" | "light" ident) fields [";"]`
    let keyword = move |t: Token, name: &'static str| {
        just(t).map_with(move |_, e| Ident {
            name: name.to_string(),
            span: sp(file, e.span()),
        })
    };
    let block = choice((
        keyword(Token::Camera, "camera").then(empty().to(None)),
        keyword(Token::Render, "render").then(empty().to(None)),
        keyword(Token::Light, "light").then(ident(file).map(Some)),
    ))
    .then(fields.clone())
    .then_ignore(just(Token::Semi).or_not())
    .map_with(move |((keyword, kind), fields), e| {
        Item::Block(Block {
            keyword,
            kind,
            fields,
            span: sp(file, e.span()),
        })
    });

    // `stmt = let | for | expr ";"`
    let stmt = recursive(|stmt| {
        let for_stmt = just(Token::For)
            .ignore_then(ident(file))
            .then_ignore(just(Token::In))
            .then(expr.clone())
            .then_ignore(just(Token::DotDot))
            .then(expr.clone())
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
        // A broken statement is skipped to its `;` (or to the `}` closing the block).
        let skip_stmt = none_of([Token::RBrace])
            .then(none_of([Token::Semi, Token::RBrace]).repeated())
            .then(just(Token::Semi).or_not())
            .map_with(move |_, e| Stmt::Error(sp(file, e.span())));
        choice((
            let_decl.clone().map(Stmt::Let),
            for_stmt,
            expr.clone()
                .then_ignore(just(Token::Semi))
                .map(Stmt::Object),
        ))
        .recover_with(via_parser(skip_stmt))
        .boxed()
    });

    // `scene = "scene" "{" { stmt } "}"`
    let scene = just(Token::Scene)
        .ignore_then(
            stmt.repeated()
                .collect::<Vec<_>>()
                .delimited_by(just(Token::LBrace), just(Token::RBrace)),
        )
        .then_ignore(just(Token::Semi).or_not())
        .map_with(move |stmts, e| Item::Scene {
            stmts,
            span: sp(file, e.span()),
        });

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
        import,
        let_decl.map(Item::Let),
        param_decl.map(Item::Let),
        function,
        material,
        block,
        scene,
    ))
    .labelled("item")
    .recover_with(via_parser(skip_item));

    item.repeated()
        .collect::<Vec<_>>()
        .then_ignore(end())
        .map(|items| File { items })
}
