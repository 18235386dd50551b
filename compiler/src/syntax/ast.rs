//! The abstract syntax tree of one `.sdf` file, with a span on every node.
//!
//! Node names follow the rules of `grammar/sdf.ebnf`. The tree is produced by
//! [`super::parse`] even when there are syntax errors: broken parts become
//! [`ExprKind::Error`] or [`Item::Error`].

use crate::span::Span;

/// A name and where it was written.
#[derive(Debug, Clone, PartialEq)]
pub struct Ident {
    /// The name.
    pub name: String,
    /// Its span.
    pub span: Span,
}

/// One source file: `file = { item }`.
#[derive(Debug, Clone, PartialEq)]
pub struct File {
    /// Items in source order.
    pub items: Vec<Item>,
}

/// `item = import | let | parameter | fn | material | camera | light | render | scene`.
#[derive(Debug, Clone, PartialEq)]
pub enum Item {
    /// `import "path";`
    Import { path: String, span: Span },
    /// `let name [: type] = expr;`
    Let(Let),
    /// `fn name(params) -> type { body }`
    Fn(FnDecl),
    /// `material name = kind { fields }`
    Material {
        name: Ident,
        kind: Ident,
        fields: Vec<Field>,
        span: Span,
    },
    /// `camera { fields }`, `render { fields }`, `light kind { fields }`: a block of settings.
    Block(Block),
    /// `scene { statements }`
    Scene { stmts: Vec<Stmt>, span: Span },
    /// An item that did not parse (already reported).
    Error(Span),
}

/// A settings block such as `camera { ... }` or `light point { ... }`.
#[derive(Debug, Clone, PartialEq)]
pub struct Block {
    /// `camera`, `render` or `light`.
    pub keyword: Ident,
    /// The light's kind (`point`, `directional`); `None` for camera and render.
    pub kind: Option<Ident>,
    /// The fields.
    pub fields: Vec<Field>,
    /// The whole block.
    pub span: Span,
}

/// `name: expr` inside a block.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    /// The field's name.
    pub name: Ident,
    /// Its value.
    pub value: Expr,
}

/// `let name [: type] = value;`, or a parameter, `param name = value [in …] ["doc"];`.
#[derive(Debug, Clone, PartialEq)]
pub struct Let {
    /// The bound name.
    pub name: Ident,
    /// The declared type, if any (see [`Param::ty`]).
    pub ty: Option<Ident>,
    /// The value (a parameter's default).
    pub value: Expr,
    /// What makes it a parameter a user may set from outside (`--param name=value`).
    pub param: Option<Box<ParamSpec>>,
    /// The whole declaration.
    pub span: Span,
}

/// The values a `param` accepts and what it is: `in lo..hi [step s]` for a number, `in
/// [choices]` for a string, and a description.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamSpec {
    /// `lo..hi`.
    pub range: Option<(Expr, Expr)>,
    /// `step s` after the range.
    pub step: Option<Expr>,
    /// `in [a, b, …]`: the strings it may be.
    pub choices: Option<Expr>,
    /// The description, a string.
    pub doc: Option<Expr>,
}

/// A user function.
#[derive(Debug, Clone, PartialEq)]
pub struct FnDecl {
    /// Its name.
    pub name: Ident,
    /// Parameters in order.
    pub params: Vec<Param>,
    /// The declared return type.
    pub ret: Ident,
    /// The body.
    pub body: Body,
    /// The whole declaration.
    pub span: Span,
}

/// `name: type [= default]`
#[derive(Debug, Clone, PartialEq)]
pub struct Param {
    /// The parameter's name.
    pub name: Ident,
    /// Its type, as written: a name (`float`) or a list type (`[shape]`), whose name is the
    /// brackets and the element type without spaces and whose span covers the brackets.
    pub ty: Ident,
    /// Its default value.
    pub default: Option<Expr>,
}

/// `{ let ...; let ...; expr }`: local bindings, then the value.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    /// Local bindings in order.
    pub lets: Vec<Let>,
    /// The value of the body.
    pub value: Box<Expr>,
    /// The braces and all inside.
    pub span: Span,
}

/// A statement of a `scene` block.
#[derive(Debug, Clone, PartialEq)]
pub enum Stmt {
    /// `let name = expr;`
    Let(Let),
    /// `expr;`: a shape added to the scene (usually `shape @ material`).
    Object(Expr),
    /// `for name in from..to { statements }`: statements repeated with `name` an int.
    For {
        var: Ident,
        from: Expr,
        to: Expr,
        body: Vec<Stmt>,
        span: Span,
    },
    /// A statement that did not parse (already reported).
    Error(Span),
}

/// An expression.
#[derive(Debug, Clone, PartialEq)]
pub struct Expr {
    /// What it is.
    pub kind: ExprKind,
    /// Where it is.
    pub span: Span,
}

impl Drop for Expr {
    /// Drops the operands by a loop over a stack of them, not by recursion: a chain (`1 + 2 +
    /// …`, `s.translate(…).rotate(…)…`, `xs[0][1]…`) is a tree as deep as it is long, up to
    /// ten times the `nesting` limit and more in a file the checker refuses for it, and its
    /// recursive drop, a few frames a link, overflowed a 2 MiB stack in a debug build.
    fn drop(&mut self) {
        let mut stack: Vec<Expr> = Vec::new();
        let mut kind = std::mem::replace(&mut self.kind, ExprKind::Error);
        loop {
            match kind {
                ExprKind::Unary(_, a)
                | ExprKind::Field(a, _)
                | ExprKind::Material(a, _)
                | ExprKind::Method { receiver: a, .. }
                | ExprKind::If { cond: a, .. } => stack.push(*a),
                ExprKind::Binary(_, a, b)
                | ExprKind::Index(a, b)
                | ExprKind::Comprehension {
                    from: a,
                    to: b,
                    cond: None,
                    ..
                } => {
                    stack.push(*a);
                    stack.push(*b);
                }
                ExprKind::Comprehension {
                    from: a,
                    to: b,
                    cond: Some(c),
                    ..
                } => {
                    stack.push(*a);
                    stack.push(*b);
                    stack.push(*c);
                }
                _ => {}
            }
            let Some(mut e) = stack.pop() else {
                break;
            };
            // `e` keeps no operands, so its own drop at the end of this turn does not recurse.
            kind = std::mem::replace(&mut e.kind, ExprKind::Error);
        }
    }
}

/// Binary operators, by precedence from loosest to tightest: `||`, `&&`, comparisons,
/// `+ -`, `* / %`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BinOp {
    Or,
    And,
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
    Add,
    Sub,
    Mul,
    Div,
    Rem,
}

impl BinOp {
    /// The operator as written.
    pub fn symbol(self) -> &'static str {
        match self {
            BinOp::Or => "||",
            BinOp::And => "&&",
            BinOp::Eq => "==",
            BinOp::Ne => "!=",
            BinOp::Lt => "<",
            BinOp::Le => "<=",
            BinOp::Gt => ">",
            BinOp::Ge => ">=",
            BinOp::Add => "+",
            BinOp::Sub => "-",
            BinOp::Mul => "*",
            BinOp::Div => "/",
            BinOp::Rem => "%",
        }
    }
}

/// Unary operators.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UnOp {
    /// `-x`
    Neg,
    /// `!x`
    Not,
}

/// A call argument, positional or named.
#[derive(Debug, Clone, PartialEq)]
pub struct Arg {
    /// `name:` for a named argument.
    pub name: Option<Ident>,
    /// The value.
    pub value: Expr,
}

/// The kinds of expression.
#[derive(Debug, Clone, PartialEq)]
pub enum ExprKind {
    /// `42`
    Int(i64),
    /// `0.5`, `1e-4`
    Float(f64),
    /// `45deg`, `0.5rad` (stored in radians)
    Angle(f64),
    /// `#rrggbb`: the sRGB bytes as written (the checker makes them a linear vec3).
    Colour([u8; 3]),
    /// `true`, `false`
    Bool(bool),
    /// `"text"`
    Str(String),
    /// A name.
    Var(Ident),
    /// `(a, b)` or `(a, b, c)`: a vector.
    Tuple(Vec<Expr>),
    /// `-x`, `!x`
    Unary(UnOp, Box<Expr>),
    /// `a op b`
    Binary(BinOp, Box<Expr>, Box<Expr>),
    /// `f(args)`
    Call { callee: Ident, args: Vec<Arg> },
    /// `receiver.f(args)`: the receiver is passed as the first parameter of its type.
    Method {
        receiver: Box<Expr>,
        name: Ident,
        args: Vec<Arg>,
    },
    /// `v.x`: a vector component.
    Field(Box<Expr>, Ident),
    /// `if cond { a } else { b }`
    If {
        cond: Box<Expr>,
        then: Body,
        otherwise: Body,
    },
    /// `shape @ material`
    Material(Box<Expr>, Ident),
    /// `[a, b, c]`: a list of values of one type.
    List(Vec<Expr>),
    /// `[for name in from..to { body }]`: a list of the body's values, `name` an int from
    /// `from` up to `to` (excluded); with `if cond` before the body, of those where `cond`
    /// holds.
    Comprehension {
        var: Ident,
        from: Box<Expr>,
        to: Box<Expr>,
        cond: Option<Box<Expr>>,
        body: Body,
    },
    /// `xs[i]`: an element of a list.
    Index(Box<Expr>, Box<Expr>),
    /// `field [args] { body }`: a shape whose distance is the body's value at the point `p`
    /// (the arguments: `lipschitz`, a declared bound of its gradient); `profile [args] {
    /// body }` (`plane`): a profile, the same of a point `p` of the plane (a vec2).
    FieldBlock {
        args: Vec<Arg>,
        body: Body,
        plane: bool,
    },
    /// An expression that did not parse (already reported).
    Error,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::span::FileId;

    /// A chain of 200 000 links, operators, method calls, components and indices, drops on a
    /// test thread's 2 MiB stack.
    #[test]
    fn a_long_chain_drops_on_a_small_stack() {
        let at = Span::new(FileId(0), 0..1);
        let leaf = || Expr {
            kind: ExprKind::Int(1),
            span: at,
        };
        let name = Ident {
            name: "f".into(),
            span: at,
        };
        let mut e = leaf();
        for i in 0..200_000 {
            let link = Box::new(e);
            let kind = match i % 4 {
                0 => ExprKind::Binary(BinOp::Add, link, Box::new(leaf())),
                1 => ExprKind::Method {
                    receiver: link,
                    name: name.clone(),
                    args: vec![Arg {
                        name: None,
                        value: leaf(),
                    }],
                },
                2 => ExprKind::Field(link, name.clone()),
                _ => ExprKind::Index(link, Box::new(leaf())),
            };
            e = Expr { kind, span: at };
        }
        drop(e);
    }
}
