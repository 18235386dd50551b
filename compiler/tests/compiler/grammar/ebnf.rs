//! The grammar's EBNF read: its terms, its notation's tokens and the reader (which panics
//! with the line on malformed input).

/// The token classes of the grammar, written in capitals.
pub(super) const CLASSES: [&str; 7] =
    ["IDENT", "INT", "FLOAT", "ANGLE", "COLOUR", "STRING", "BOOL"];

/// A right-hand side of the EBNF.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Ebnf {
    /// A rule by name (lower case).
    Rule(String),
    /// A quoted terminal: a keyword or punctuation, by its text.
    Lit(String),
    /// A token class such as `IDENT`.
    Class(String),
    Seq(Vec<Ebnf>),
    Alt(Vec<Ebnf>),
    /// `{ x }`
    Rep(Box<Ebnf>),
    /// `[ x ]`
    Opt(Box<Ebnf>),
}

/// A grammar: its rules in file order.
#[derive(Debug)]
pub(super) struct Grammar {
    pub(super) rules: Vec<(String, Ebnf)>,
}

impl Grammar {
    pub(super) fn get(&self, name: &str) -> Option<usize> {
        self.rules.iter().position(|(n, _)| n == name)
    }
}

// ---- Reading the EBNF ----

/// A token of the EBNF notation itself.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Meta {
    Name(String),
    Class(String),
    Str(String),
    Punct(char),
}

/// Splits EBNF text into tokens, skipping `(* comments *)`; the line of each token is kept
/// for error messages.
pub(super) fn meta_tokens(text: &str) -> Vec<(Meta, usize)> {
    let chars: Vec<char> = text.chars().collect();
    let (mut out, mut i, mut line) = (Vec::new(), 0, 1);
    while i < chars.len() {
        let c = chars[i];
        if c == '\n' {
            line += 1;
        }
        if c.is_whitespace() {
            i += 1;
        } else if c == '(' && chars.get(i + 1) == Some(&'*') {
            let end = (i + 2..chars.len() - 1)
                .find(|&j| chars[j] == '*' && chars[j + 1] == ')')
                .unwrap_or_else(|| panic!("sdf.ebnf:{line}: unclosed comment"));
            line += chars[i..end].iter().filter(|&&c| c == '\n').count();
            i = end + 2;
        } else if c == '"' {
            let end = (i + 1..chars.len())
                .find(|&j| chars[j] == '"' || chars[j] == '\n')
                .filter(|&j| chars[j] == '"')
                .unwrap_or_else(|| panic!("sdf.ebnf:{line}: unclosed terminal"));
            out.push((Meta::Str(chars[i + 1..end].iter().collect()), line));
            i = end + 1;
        } else if c.is_ascii_alphabetic() || c == '_' {
            let end = (i..chars.len())
                .find(|&j| !(chars[j].is_ascii_alphanumeric() || chars[j] == '_'))
                .unwrap_or(chars.len());
            let word: String = chars[i..end].iter().collect();
            let is_class = word.chars().all(|c| c.is_ascii_uppercase() || c == '_');
            out.push((
                if is_class {
                    Meta::Class(word)
                } else {
                    Meta::Name(word)
                },
                line,
            ));
            i = end;
        } else if "=|;{}[]()".contains(c) {
            out.push((Meta::Punct(c), line));
            i += 1;
        } else {
            panic!("sdf.ebnf:{line}: unexpected character {c:?}");
        }
    }
    out
}

/// A recursive-descent reader of the EBNF notation.
pub(super) struct Reader {
    toks: Vec<(Meta, usize)>,
    pos: usize,
}

impl Reader {
    fn peek(&self) -> Option<&Meta> {
        self.toks.get(self.pos).map(|(m, _)| m)
    }

    fn line(&self) -> usize {
        self.toks
            .get(self.pos)
            .or(self.toks.last())
            .map_or(0, |(_, l)| *l)
    }

    fn expect(&mut self, c: char) {
        if self.peek() != Some(&Meta::Punct(c)) {
            panic!(
                "sdf.ebnf:{}: expected `{c}`, found {:?}",
                self.line(),
                self.peek()
            );
        }
        self.pos += 1;
    }

    /// `rule = name "=" alternatives ";"`
    fn rule(&mut self) -> (String, Ebnf) {
        let name = match self.peek() {
            Some(Meta::Name(n)) => n.clone(),
            other => panic!(
                "sdf.ebnf:{}: expected a rule name, found {other:?}",
                self.line()
            ),
        };
        self.pos += 1;
        self.expect('=');
        let rhs = self.alternatives();
        self.expect(';');
        (name, rhs)
    }

    /// `alternatives = sequence { "|" sequence }`
    fn alternatives(&mut self) -> Ebnf {
        let mut alts = vec![self.sequence()];
        while self.peek() == Some(&Meta::Punct('|')) {
            self.pos += 1;
            alts.push(self.sequence());
        }
        if alts.len() == 1 {
            alts.pop().expect("one")
        } else {
            Ebnf::Alt(alts)
        }
    }

    /// `sequence = factor { factor }`
    fn sequence(&mut self) -> Ebnf {
        let mut items = Vec::new();
        while let Some(f) = self.factor() {
            items.push(f);
        }
        if items.is_empty() {
            panic!("sdf.ebnf:{}: empty alternative", self.line());
        }
        if items.len() == 1 {
            items.pop().expect("one")
        } else {
            Ebnf::Seq(items)
        }
    }

    /// `factor = name | CLASS | terminal | "{" alternatives "}" | "[" ... "]" | "(" ... ")"`
    fn factor(&mut self) -> Option<Ebnf> {
        let tok = self.peek()?.clone();
        let group = |r: &mut Reader, close: char| {
            r.pos += 1;
            let inner = r.alternatives();
            r.expect(close);
            inner
        };
        Some(match tok {
            Meta::Name(n) => {
                self.pos += 1;
                Ebnf::Rule(n)
            }
            Meta::Class(c) => {
                self.pos += 1;
                Ebnf::Class(c)
            }
            Meta::Str(s) => {
                self.pos += 1;
                Ebnf::Lit(s)
            }
            Meta::Punct('{') => Ebnf::Rep(Box::new(group(self, '}'))),
            Meta::Punct('[') => Ebnf::Opt(Box::new(group(self, ']'))),
            Meta::Punct('(') => group(self, ')'),
            Meta::Punct(_) => return None,
        })
    }
}

/// Reads EBNF text into a grammar; panics with the line on malformed input.
pub(super) fn read_grammar(text: &str) -> Grammar {
    let mut r = Reader {
        toks: meta_tokens(text),
        pos: 0,
    };
    let mut rules = Vec::new();
    while r.peek().is_some() {
        rules.push(r.rule());
    }
    Grammar { rules }
}
