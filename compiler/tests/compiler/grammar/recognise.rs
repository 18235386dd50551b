//! Token streams recognised by the grammar: the lexer's tokens as the grammar's terminals,
//! and a memoised backtracking recogniser that returns every position where a rule can end.

use super::*;

/// What a token is to the grammar: a quoted terminal or a token class.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(super) enum Sym {
    Lit(&'static str),
    Class(&'static str),
}

/// Maps a lexer token to the grammar's terminal. The match is exhaustive, so a new token
/// cannot be added to the lexer without deciding its place in the grammar.
pub(super) fn terminal(t: &Token) -> Sym {
    use Sym::{Class, Lit};
    match t {
        Token::Import => Lit("import"),
        Token::Let => Lit("let"),
        Token::Param => Lit("param"),
        Token::Fn => Lit("fn"),
        Token::Material => Lit("material"),
        Token::Camera => Lit("camera"),
        Token::Light => Lit("light"),
        Token::Render => Lit("render"),
        Token::Scene => Lit("scene"),
        Token::If => Lit("if"),
        Token::Else => Lit("else"),
        Token::For => Lit("for"),
        Token::In => Lit("in"),
        Token::Bool(_) => Class("BOOL"),
        Token::Int(_) => Class("INT"),
        Token::Float(_) => Class("FLOAT"),
        Token::Angle(_) => Class("ANGLE"),
        Token::Colour(_) => Class("COLOUR"),
        Token::Str(_) => Class("STRING"),
        Token::Ident(_) => Class("IDENT"),
        // Never produced by `lex`: it scans a string from its quote, or drops a comment.
        Token::Quote => Lit("\""),
        Token::BlockComment => Lit("/*"),
        Token::LParen => Lit("("),
        Token::RParen => Lit(")"),
        Token::LBrace => Lit("{"),
        Token::RBrace => Lit("}"),
        Token::LBracket => Lit("["),
        Token::RBracket => Lit("]"),
        Token::Comma => Lit(","),
        Token::Semi => Lit(";"),
        Token::Colon => Lit(":"),
        Token::Dot => Lit("."),
        Token::DotDot => Lit(".."),
        Token::At => Lit("@"),
        Token::Eq => Lit("="),
        Token::Arrow => Lit("->"),
        Token::Plus => Lit("+"),
        Token::Minus => Lit("-"),
        Token::Star => Lit("*"),
        Token::Slash => Lit("/"),
        Token::Percent => Lit("%"),
        Token::Lt => Lit("<"),
        Token::Le => Lit("<="),
        Token::Gt => Lit(">"),
        Token::Ge => Lit(">="),
        Token::EqEq => Lit("=="),
        Token::Ne => Lit("!="),
        Token::AndAnd => Lit("&&"),
        Token::OrOr => Lit("||"),
        Token::Bang => Lit("!"),
    }
}

/// The recogniser's state for one token stream.
pub(super) struct Recogniser<'g> {
    g: &'g Grammar,
    input: Vec<Sym>,
    /// Every end position of (rule, start); `None` while being computed (left recursion).
    memo: HashMap<(usize, usize), Option<BTreeSet<usize>>>,
    /// The furthest position where a terminal was tried, and what was expected there.
    furthest: usize,
    expected: BTreeSet<String>,
}

impl<'g> Recogniser<'g> {
    fn new(g: &'g Grammar, input: Vec<Sym>) -> Self {
        Recogniser {
            g,
            input,
            memo: HashMap::new(),
            furthest: 0,
            expected: BTreeSet::new(),
        }
    }

    /// Matches one quoted terminal or token class at `pos`.
    fn terminal(&mut self, want: &Ebnf, pos: usize) -> BTreeSet<usize> {
        let (text, shown) = match want {
            Ebnf::Lit(s) => (s.as_str(), format!("\"{s}\"")),
            Ebnf::Class(c) => (c.as_str(), c.clone()),
            _ => unreachable!("not a terminal"),
        };
        let hit = match self.input.get(pos) {
            Some(Sym::Lit(s)) => matches!(want, Ebnf::Lit(_)) && *s == text,
            Some(Sym::Class(c)) => matches!(want, Ebnf::Class(_)) && *c == text,
            None => false,
        };
        if hit {
            return BTreeSet::from([pos + 1]);
        }
        if pos > self.furthest {
            self.furthest = pos;
            self.expected.clear();
        }
        if pos == self.furthest {
            self.expected.insert(shown);
        }
        BTreeSet::new()
    }

    fn rule(&mut self, name: &str, pos: usize) -> BTreeSet<usize> {
        let idx = self
            .g
            .get(name)
            .unwrap_or_else(|| panic!("undefined rule `{name}`"));
        match self.memo.get(&(idx, pos)) {
            Some(Some(ends)) => return ends.clone(),
            Some(None) => panic!("rule `{name}` is left-recursive"),
            None => {}
        }
        self.memo.insert((idx, pos), None);
        let rhs = self.g.rules[idx].1.clone();
        let ends = self.ends(&rhs, pos);
        self.memo.insert((idx, pos), Some(ends.clone()));
        ends
    }

    /// Every position where `e`, started at `pos`, can end.
    fn ends(&mut self, e: &Ebnf, pos: usize) -> BTreeSet<usize> {
        match e {
            Ebnf::Rule(n) => self.rule(n, pos),
            Ebnf::Lit(_) | Ebnf::Class(_) => self.terminal(e, pos),
            Ebnf::Seq(items) => {
                let mut at = BTreeSet::from([pos]);
                for item in items {
                    at = at.into_iter().flat_map(|p| self.ends(item, p)).collect();
                    if at.is_empty() {
                        break;
                    }
                }
                at
            }
            Ebnf::Alt(alts) => alts.iter().flat_map(|a| self.ends(a, pos)).collect(),
            Ebnf::Opt(x) => {
                let mut at = self.ends(x, pos);
                at.insert(pos);
                at
            }
            Ebnf::Rep(x) => self.repeat(x, pos),
        }
    }

    fn repeat(&mut self, x: &Ebnf, pos: usize) -> BTreeSet<usize> {
        let mut all = BTreeSet::from([pos]);
        let mut frontier = vec![pos];
        while let Some(p) = frontier.pop() {
            for q in self.ends(x, p) {
                if all.insert(q) {
                    frontier.push(q);
                }
            }
        }
        all
    }
}

/// Why a text is not recognised.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) enum Unrecognised {
    /// The lexer's messages.
    Lexical(Vec<String>),
    /// Not the rule `start`: where the input stops fitting and what would have fitted there.
    Stuck {
        start: String,
        at: String,
        expected: Vec<String>,
    },
}

impl std::fmt::Display for Unrecognised {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Unrecognised::Lexical(messages) => write!(f, "lexical errors: {messages:?}"),
            Unrecognised::Stuck {
                start,
                at,
                expected,
            } => write!(
                f,
                "not a `{start}`: stuck at {at}; expected one of {}",
                expected.join(" ")
            ),
        }
    }
}

/// Recognises `text` from the rule `start`, or says where the input stops fitting.
pub(super) fn recognise(g: &Grammar, start: &str, text: &str) -> Result<(), Unrecognised> {
    let (tokens, diags) = lex(FileId(0), text);
    if !diags.is_empty() {
        return Err(Unrecognised::Lexical(
            diags.iter().map(|d| d.message.clone()).collect(),
        ));
    }
    let input: Vec<Sym> = tokens.iter().map(|(t, _)| terminal(t)).collect();
    let n = input.len();
    let mut r = Recogniser::new(g, input);
    if r.rule(start, 0).contains(&n) {
        return Ok(());
    }
    let at = tokens.get(r.furthest).map_or_else(
        || "the end of the file".to_string(),
        |(t, s)| {
            let line = text[..s.start as usize].matches('\n').count() + 1;
            format!("{t} on line {line}")
        },
    );
    Err(Unrecognised::Stuck {
        start: start.into(),
        at,
        expected: r.expected.into_iter().collect(),
    })
}

/// Runs `f` on a thread with a large stack: recognition recurses once per nesting level of
/// every rule.
pub(super) fn with_stack<T: Send + 'static>(f: impl FnOnce() -> T + Send + 'static) -> T {
    std::thread::Builder::new()
        .stack_size(64 << 20)
        .spawn(f)
        .expect("thread")
        .join()
        .expect("no panic")
}

// ---- Collecting rule names ----
