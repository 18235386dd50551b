//! A stable, indented text dump of the AST (`sdfc compile --emit ast`, snapshot tests).

use super::ast::*;

/// Dumps a file as one line per node, children indented by two spaces. Spans are left out
/// so the dump is stable under edits that only move text.
pub fn dump(file: &File) -> String {
    let mut d = Dumper {
        out: String::new(),
        depth: 0,
    };
    for item in &file.items {
        d.item(item);
    }
    d.out
}

struct Dumper {
    out: String,
    depth: usize,
}

impl Dumper {
    fn line(&mut self, text: impl AsRef<str>) {
        for _ in 0..self.depth {
            self.out.push_str("  ");
        }
        self.out.push_str(text.as_ref());
        self.out.push('\n');
    }

    fn nested(&mut self, head: impl AsRef<str>, f: impl FnOnce(&mut Self)) {
        self.line(head);
        self.depth += 1;
        f(self);
        self.depth -= 1;
    }

    fn item(&mut self, item: &Item) {
        match item {
            Item::Import { path, .. } => self.line(format!("import {path:?}")),
            Item::Let(l) => self.let_(l),
            Item::Fn(f) => self.nested(format!("fn {} -> {}", f.name.name, f.ret.name), |d| {
                for p in &f.params {
                    match &p.default {
                        Some(def) => d
                            .nested(format!("param {}: {} =", p.name.name, p.ty.name), |d| {
                                d.expr(def)
                            }),
                        None => d.line(format!("param {}: {}", p.name.name, p.ty.name)),
                    }
                }
                d.body(&f.body);
            }),
            Item::Material {
                name, kind, fields, ..
            } => self.nested(format!("material {} = {}", name.name, kind.name), |d| {
                d.fields(fields)
            }),
            Item::Block(b) => {
                let head = match &b.kind {
                    Some(k) => format!("{} {}", b.keyword.name, k.name),
                    None => b.keyword.name.clone(),
                };
                self.nested(head, |d| d.fields(&b.fields))
            }
            Item::Scene { stmts, .. } => self.nested("scene", |d| d.stmts(stmts)),
            Item::Error(_) => self.line("<error>"),
        }
    }

    fn fields(&mut self, fields: &[Field]) {
        for f in fields {
            self.nested(format!("{}:", f.name.name), |d| d.expr(&f.value));
        }
    }

    fn let_(&mut self, l: &Let) {
        let head = match &l.ty {
            Some(t) => format!("let {}: {}", l.name.name, t.name),
            None => format!("let {}", l.name.name),
        };
        self.nested(head, |d| d.expr(&l.value));
    }

    fn body(&mut self, b: &Body) {
        self.nested("body", |d| {
            for l in &b.lets {
                d.let_(l);
            }
            d.expr(&b.value);
        });
    }

    fn stmts(&mut self, stmts: &[Stmt]) {
        for s in stmts {
            match s {
                Stmt::Let(l) => self.let_(l),
                Stmt::Object(e) => self.nested("object", |d| d.expr(e)),
                Stmt::For {
                    var,
                    from,
                    to,
                    body,
                    ..
                } => self.nested(format!("for {}", var.name), |d| {
                    d.expr(from);
                    d.expr(to);
                    d.nested("do", |d| d.stmts(body));
                }),
                Stmt::Error(_) => self.line("<error>"),
            }
        }
    }

    fn args(&mut self, args: &[Arg]) {
        for a in args {
            match &a.name {
                Some(n) => self.nested(format!("{}:", n.name), |d| d.expr(&a.value)),
                None => self.expr(&a.value),
            }
        }
    }

    fn expr(&mut self, e: &Expr) {
        match &e.kind {
            ExprKind::Int(v) => self.line(format!("int {v}")),
            ExprKind::Float(v) => self.line(format!("float {v:?}")),
            ExprKind::Angle(v) => self.line(format!("angle {v:?}rad")),
            ExprKind::Colour([r, g, b]) => self.line(format!("colour #{r:02x}{g:02x}{b:02x}")),
            ExprKind::Bool(v) => self.line(format!("bool {v}")),
            ExprKind::Str(v) => self.line(format!("string {v:?}")),
            ExprKind::Var(id) => self.line(format!("var {}", id.name)),
            ExprKind::Tuple(items) => {
                self.nested("tuple", |d| items.iter().for_each(|i| d.expr(i)))
            }
            ExprKind::Unary(op, x) => {
                let sym = if *op == UnOp::Neg { "-" } else { "!" };
                self.nested(format!("unary {sym}"), |d| d.expr(x))
            }
            ExprKind::Binary(op, a, b) => self.nested(format!("binary {}", op.symbol()), |d| {
                d.expr(a);
                d.expr(b);
            }),
            ExprKind::Call { callee, args } => {
                self.nested(format!("call {}", callee.name), |d| d.args(args))
            }
            ExprKind::Method {
                receiver,
                name,
                args,
            } => self.nested(format!("method {}", name.name), |d| {
                d.expr(receiver);
                d.args(args);
            }),
            ExprKind::Field(x, name) => self.nested(format!("field {}", name.name), |d| d.expr(x)),
            ExprKind::If {
                cond,
                then,
                otherwise,
            } => self.nested("if", |d| {
                d.expr(cond);
                d.body(then);
                d.body(otherwise);
            }),
            ExprKind::Material(x, m) => self.nested(format!("material @{}", m.name), |d| d.expr(x)),
            ExprKind::List(items) => self.nested("list", |d| items.iter().for_each(|i| d.expr(i))),
            ExprKind::Comprehension {
                var,
                from,
                to,
                cond,
                body,
            } => self.nested(format!("list for {}", var.name), |d| {
                d.expr(from);
                d.expr(to);
                if let Some(c) = cond {
                    d.nested("if", |d| d.expr(c));
                }
                d.body(body);
            }),
            ExprKind::Index(xs, i) => self.nested("index", |d| {
                d.expr(xs);
                d.expr(i);
            }),
            ExprKind::FieldBlock { args, body, plane } => {
                self.nested(if *plane { "profile" } else { "field" }, |d| {
                    for a in args {
                        match &a.name {
                            Some(n) => d.nested(format!("arg {}", n.name), |d| d.expr(&a.value)),
                            None => d.expr(&a.value),
                        }
                    }
                    d.body(body);
                })
            }
            ExprKind::Error => self.line("<error>"),
        }
    }
}
