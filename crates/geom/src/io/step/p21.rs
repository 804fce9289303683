//! The clear-text encoding of ISO 10303-21 (the STEP exchange file): a lexer and a parser that turn the bytes into
//! entity instances by instance number, with the data section's values kept as written.
//!
//! Read: the `ISO-10303-21;` opening, the `HEADER;` section (parsed for syntax, then dropped), one or more `DATA;`
//! sections (with or without the edition-3 parameter list) of simple instances `#n = NAME(args);` and complex
//! instances `#n = ( A(args) B(args) );`, and `END-ISO-10303-21;` (anything after it is ignored). Values: strings
//! with `''` escapes (other `\` directives are kept as written), integers, reals (`1.E-07`, `-0.`), enumerations
//! (`.T.`, `.MILLI.`), binaries (`"0FF"`), `$`, `*`, `#n` references, nested lists and typed parameters such as
//! `LENGTH_MEASURE(25.4)`. `/* comments */` count as white space.
//!
//! Every error carries the 1-based line where it is. The lexer makes one pass over the bytes and the parameter
//! parser keeps its open lists on an explicit stack, capped at [`MAX_NESTING`] levels, so parsing is linear in the
//! file size whatever the input and never recurses.

use std::collections::HashMap;
use std::collections::hash_map::Entry;

/// Deepest accepted nesting of parameter lists and typed parameters (real files use at most 3 or 4).
pub(crate) const MAX_NESTING: usize = 64;

/// A parse error: what is wrong and the 1-based line.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ParseError {
    /// 1-based line.
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

/// One parameter value.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Value {
    /// An integer.
    Integer(i64),
    /// A real.
    Real(f64),
    /// A string, `''` unescaped.
    String(String),
    /// An enumeration (or logical) value without its dots: `T`, `MILLI`.
    Enum(String),
    /// A binary value, its hexadecimal text as written.
    Binary(String),
    /// A reference to an instance: `#17` is 17.
    Ref(u64),
    /// `$`: no value.
    Unset,
    /// `*`: a value derived by the schema.
    Derived,
    /// A list.
    List(Vec<Value>),
    /// A typed parameter: `LENGTH_MEASURE(25.4)`.
    Typed(String, Box<Value>),
}

/// One entity record: its type name (upper case) and its arguments.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Record {
    /// The entity type name, upper case.
    pub name: String,
    /// The arguments.
    pub args: Vec<Value>,
}

/// The body of an instance.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Body {
    /// `#n = NAME(args);`
    Simple(Record),
    /// `#n = ( A(args) B(args) );`: the records of a complex instance, in file order.
    Complex(Vec<Record>),
}

/// One entity instance of the data section.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Instance {
    /// The 1-based line of its `#n`.
    pub line: usize,
    /// Its record(s).
    pub body: Body,
}

impl Instance {
    /// The record named `name`: the instance itself when simple, one of its records when complex.
    pub fn record(&self, name: &str) -> Option<&Record> {
        match &self.body {
            Body::Simple(r) => (r.name == name).then_some(r),
            Body::Complex(rs) => rs.iter().find(|r| r.name == name),
        }
    }

    /// The type name for messages: the simple record's name, or the complex instance's names joined by spaces in
    /// parentheses.
    pub fn type_name(&self) -> String {
        match &self.body {
            Body::Simple(r) => r.name.clone(),
            Body::Complex(rs) => {
                let names: Vec<&str> = rs.iter().map(|r| r.name.as_str()).collect();
                format!("({})", names.join(" "))
            }
        }
    }
}

/// The data sections of an exchange file.
#[derive(Debug, Clone, Default)]
pub(crate) struct Exchange {
    /// The instances by instance number.
    pub instances: HashMap<u64, Instance>,
    /// The instance numbers in file order.
    pub order: Vec<u64>,
}

/// Parses an exchange file.
pub(crate) fn parse(bytes: &[u8]) -> Result<Exchange, ParseError> {
    let mut p = Parser { lexer: Lexer { bytes, pos: 0, line: 1 } };
    p.expect_keyword("ISO-10303-21")?;
    p.expect(&Tok::Semi, "`;` after ISO-10303-21")?;
    p.expect_keyword("HEADER")?;
    p.expect(&Tok::Semi, "`;` after HEADER")?;
    loop {
        let (tok, line) = p.next()?;
        match tok {
            Tok::Keyword(k) if k == "ENDSEC" => {
                p.expect(&Tok::Semi, "`;` after ENDSEC")?;
                break;
            }
            Tok::Keyword(_) => {
                p.expect(&Tok::Open, "`(` after a header entity name")?;
                p.params(line)?;
                p.expect(&Tok::Semi, "`;` after a header entity")?;
            }
            other => return Err(unexpected(&other, line, "a header entity or ENDSEC")),
        }
    }
    let mut exchange = Exchange::default();
    let mut sections = 0usize;
    loop {
        let (tok, line) = p.next()?;
        match tok {
            Tok::Keyword(k) if k == "DATA" => {
                sections += 1;
                let (tok, line) = p.next()?;
                match tok {
                    Tok::Semi => {}
                    Tok::Open => {
                        p.params(line)?;
                        p.expect(&Tok::Semi, "`;` after DATA(...)")?;
                    }
                    other => return Err(unexpected(&other, line, "`;` after DATA")),
                }
                p.data_section(&mut exchange)?;
            }
            Tok::Keyword(k) if k == "END-ISO-10303-21" => {
                p.expect(&Tok::Semi, "`;` after END-ISO-10303-21")?;
                break;
            }
            other => return Err(unexpected(&other, line, "DATA or END-ISO-10303-21")),
        }
    }
    if sections == 0 {
        return Err(ParseError { line: p.lexer.line, message: "the file has no DATA section".into() });
    }
    Ok(exchange)
}

/// A token.
#[derive(Debug, Clone, PartialEq)]
enum Tok {
    /// A standard or user-defined (`!NAME`) keyword, upper case; also `ISO-10303-21` and friends.
    Keyword(String),
    /// `#n`.
    Ref(u64),
    Eq,
    Open,
    Close,
    Comma,
    Semi,
    Dollar,
    Star,
    Str(String),
    Enum(String),
    Binary(String),
    Int(i64),
    Real(f64),
    Eof,
}

fn describe(tok: &Tok) -> String {
    match tok {
        Tok::Keyword(k) => format!("`{k}`"),
        Tok::Ref(n) => format!("`#{n}`"),
        Tok::Eq => "`=`".into(),
        Tok::Open => "`(`".into(),
        Tok::Close => "`)`".into(),
        Tok::Comma => "`,`".into(),
        Tok::Semi => "`;`".into(),
        Tok::Dollar => "`$`".into(),
        Tok::Star => "`*`".into(),
        Tok::Str(_) => "a string".into(),
        Tok::Enum(e) => format!("`.{e}.`"),
        Tok::Binary(_) => "a binary".into(),
        Tok::Int(i) => format!("`{i}`"),
        Tok::Real(r) => format!("`{r}`"),
        Tok::Eof => "the end of the file".into(),
    }
}

fn unexpected(tok: &Tok, line: usize, expected: &str) -> ParseError {
    ParseError { line, message: format!("expected {expected}, found {}", describe(tok)) }
}

struct Lexer<'a> {
    bytes: &'a [u8],
    pos: usize,
    line: usize,
}

impl Lexer<'_> {
    fn error(&self, line: usize, message: impl Into<String>) -> ParseError {
        ParseError { line, message: message.into() }
    }

    /// Skips white space and comments.
    fn skip_blank(&mut self) -> Result<(), ParseError> {
        while let Some(&b) = self.bytes.get(self.pos) {
            match b {
                b'\n' => {
                    self.line += 1;
                    self.pos += 1;
                }
                b' ' | b'\t' | b'\r' | 0x0b | 0x0c => self.pos += 1,
                b'/' if self.bytes.get(self.pos + 1) == Some(&b'*') => {
                    let start = self.line;
                    self.pos += 2;
                    loop {
                        match self.bytes.get(self.pos) {
                            None => return Err(self.error(start, "unterminated comment (`/*` without `*/`)")),
                            Some(b'*') if self.bytes.get(self.pos + 1) == Some(&b'/') => {
                                self.pos += 2;
                                break;
                            }
                            Some(&c) => {
                                if c == b'\n' {
                                    self.line += 1;
                                }
                                self.pos += 1;
                            }
                        }
                    }
                }
                _ => break,
            }
        }
        Ok(())
    }

    /// The bytes from `start` while `accept` holds, as ASCII text.
    fn take_while(&mut self, accept: impl Fn(u8) -> bool) -> String {
        let start = self.pos;
        while self.bytes.get(self.pos).is_some_and(|&b| accept(b)) {
            self.pos += 1;
        }
        // Only ASCII bytes are ever accepted, so this is the text itself.
        String::from_utf8_lossy(&self.bytes[start..self.pos]).into_owned()
    }

    fn next(&mut self) -> Result<(Tok, usize), ParseError> {
        self.skip_blank()?;
        let line = self.line;
        let Some(&b) = self.bytes.get(self.pos) else { return Ok((Tok::Eof, line)) };
        let single = |t: Tok, lx: &mut Self| {
            lx.pos += 1;
            Ok((t, line))
        };
        match b {
            b'=' => single(Tok::Eq, self),
            b'(' => single(Tok::Open, self),
            b')' => single(Tok::Close, self),
            b',' => single(Tok::Comma, self),
            b';' => single(Tok::Semi, self),
            b'$' => single(Tok::Dollar, self),
            b'*' => single(Tok::Star, self),
            b'#' => {
                self.pos += 1;
                let digits = self.take_while(|c| c.is_ascii_digit());
                if digits.is_empty() {
                    return Err(self.error(line, "`#` not followed by an instance number"));
                }
                let n = digits
                    .parse::<u64>()
                    .map_err(|_| self.error(line, format!("instance number #{digits} is too large")))?;
                Ok((Tok::Ref(n), line))
            }
            b'\'' => self.string(line),
            b'"' => {
                self.pos += 1;
                let hex = self.take_while(|c| c.is_ascii_hexdigit());
                if self.bytes.get(self.pos) != Some(&b'"') {
                    return Err(self.error(line, "unterminated binary value (`\"` without its closing `\"`)"));
                }
                self.pos += 1;
                Ok((Tok::Binary(hex), line))
            }
            b'.' => {
                self.pos += 1;
                let name = self.take_while(|c| c.is_ascii_alphanumeric() || c == b'_');
                if name.is_empty() || self.bytes.get(self.pos) != Some(&b'.') {
                    return Err(self.error(line, "malformed enumeration value (expected `.NAME.`)"));
                }
                self.pos += 1;
                Ok((Tok::Enum(name.to_ascii_uppercase()), line))
            }
            b'0'..=b'9' | b'+' | b'-' => self.number(line),
            b'!' | b'A'..=b'Z' | b'a'..=b'z' | b'_' => {
                let start = self.pos;
                self.pos += 1;
                let rest = self.take_while(|c| c.is_ascii_alphanumeric() || c == b'_' || c == b'-');
                let first = char::from(self.bytes[start]);
                Ok((Tok::Keyword(format!("{first}{rest}").to_ascii_uppercase()), line))
            }
            other => Err(self.error(line, format!("unexpected byte 0x{other:02X}"))),
        }
    }

    fn string(&mut self, line: usize) -> Result<(Tok, usize), ParseError> {
        self.pos += 1;
        let mut raw = Vec::new();
        loop {
            match self.bytes.get(self.pos) {
                None => return Err(self.error(line, "unterminated string (`'` without its closing `'`)")),
                Some(b'\'') => {
                    if self.bytes.get(self.pos + 1) == Some(&b'\'') {
                        raw.push(b'\'');
                        self.pos += 2;
                    } else {
                        self.pos += 1;
                        break;
                    }
                }
                Some(&c) => {
                    if c == b'\n' {
                        self.line += 1;
                    }
                    raw.push(c);
                    self.pos += 1;
                }
            }
        }
        Ok((Tok::Str(String::from_utf8_lossy(&raw).into_owned()), line))
    }

    fn number(&mut self, line: usize) -> Result<(Tok, usize), ParseError> {
        let start = self.pos;
        if matches!(self.bytes.get(self.pos), Some(b'+' | b'-')) {
            self.pos += 1;
        }
        let digits = |lx: &mut Self| {
            let s = lx.pos;
            while lx.bytes.get(lx.pos).is_some_and(u8::is_ascii_digit) {
                lx.pos += 1;
            }
            lx.pos - s
        };
        let whole = digits(self);
        let mut real = false;
        if self.bytes.get(self.pos) == Some(&b'.') {
            real = true;
            self.pos += 1;
            digits(self);
        }
        if matches!(self.bytes.get(self.pos), Some(b'E' | b'e')) {
            real = true;
            self.pos += 1;
            if matches!(self.bytes.get(self.pos), Some(b'+' | b'-')) {
                self.pos += 1;
            }
            if digits(self) == 0 {
                return Err(self.error(line, "malformed number: exponent without digits"));
            }
        }
        let text = String::from_utf8_lossy(&self.bytes[start..self.pos]).into_owned();
        if whole == 0 {
            return Err(self.error(line, format!("malformed number `{text}`")));
        }
        if real {
            let value = text.parse::<f64>().map_err(|_| self.error(line, format!("malformed number `{text}`")))?;
            Ok((Tok::Real(value), line))
        } else {
            let value = text.parse::<i64>().map_err(|_| self.error(line, format!("integer `{text}` is too large")))?;
            Ok((Tok::Int(value), line))
        }
    }
}

struct Parser<'a> {
    lexer: Lexer<'a>,
}

/// An open list (or typed parameter) on the parameter parser's stack.
struct Open {
    items: Vec<Value>,
    /// `Some(name)` for a typed parameter `NAME(value)`.
    typed: Option<String>,
    line: usize,
}

impl Parser<'_> {
    fn next(&mut self) -> Result<(Tok, usize), ParseError> {
        self.lexer.next()
    }

    fn expect(&mut self, want: &Tok, what: &str) -> Result<usize, ParseError> {
        let (tok, line) = self.next()?;
        if &tok == want { Ok(line) } else { Err(unexpected(&tok, line, what)) }
    }

    fn expect_keyword(&mut self, word: &str) -> Result<(), ParseError> {
        let (tok, line) = self.next()?;
        match tok {
            Tok::Keyword(k) if k == word => Ok(()),
            other => Err(unexpected(&other, line, &format!("`{word}`"))),
        }
    }

    /// Instances up to and including `ENDSEC;`.
    fn data_section(&mut self, exchange: &mut Exchange) -> Result<(), ParseError> {
        loop {
            let (tok, line) = self.next()?;
            let id = match tok {
                Tok::Ref(id) => id,
                Tok::Keyword(k) if k == "ENDSEC" => {
                    self.expect(&Tok::Semi, "`;` after ENDSEC")?;
                    return Ok(());
                }
                Tok::Eof => {
                    return Err(ParseError {
                        line,
                        message: "unexpected end of file in the DATA section (no ENDSEC)".into(),
                    });
                }
                other => return Err(unexpected(&other, line, "an instance `#n = ...;` or ENDSEC")),
            };
            self.instance_body(id, line).and_then(|body| match exchange.instances.entry(id) {
                Entry::Occupied(e) => Err(ParseError {
                    line,
                    message: format!("instance #{id} is defined twice (first at line {})", e.get().line),
                }),
                Entry::Vacant(v) => {
                    v.insert(Instance { line, body });
                    exchange.order.push(id);
                    Ok(())
                }
            })?;
        }
    }

    /// `= NAME(args);` or `= ( A(args) B(args) );` after `#id`.
    fn instance_body(&mut self, id: u64, line: usize) -> Result<Body, ParseError> {
        let in_entity = |e: ParseError| ParseError { line: e.line, message: format!("instance #{id}: {}", e.message) };
        self.expect(&Tok::Eq, "`=`").map_err(in_entity)?;
        let (tok, tok_line) = self.next().map_err(in_entity)?;
        let body = match tok {
            Tok::Keyword(name) => {
                self.expect(&Tok::Open, "`(` after the entity name").map_err(in_entity)?;
                Body::Simple(Record { name, args: self.params(line).map_err(in_entity)? })
            }
            Tok::Open => {
                let mut records = Vec::new();
                loop {
                    let (tok, tok_line) = self.next().map_err(in_entity)?;
                    match tok {
                        Tok::Keyword(name) => {
                            self.expect(&Tok::Open, "`(` after the entity name").map_err(in_entity)?;
                            records.push(Record { name, args: self.params(line).map_err(in_entity)? });
                        }
                        Tok::Close if !records.is_empty() => break,
                        other => {
                            return Err(in_entity(unexpected(&other, tok_line, "an entity name or `)`")));
                        }
                    }
                }
                Body::Complex(records)
            }
            other => return Err(in_entity(unexpected(&other, tok_line, "an entity name or `(`"))),
        };
        self.expect(&Tok::Semi, "`;` after the instance").map_err(in_entity)?;
        Ok(body)
    }

    /// The parameters of a list whose `(` has just been read, up to and including its `)`.
    fn params(&mut self, start_line: usize) -> Result<Vec<Value>, ParseError> {
        #[derive(PartialEq)]
        enum State {
            /// Right after `(`: a value or `)`.
            Start,
            /// After a value: `,` or `)`.
            AfterValue,
            /// After `,`: a value.
            AfterComma,
        }
        let mut stack = vec![Open { items: Vec::new(), typed: None, line: start_line }];
        let mut state = State::Start;
        loop {
            let (tok, line) = self.next()?;
            let value = match tok {
                Tok::Close if state != State::AfterComma => {
                    let Some(open) = stack.pop() else {
                        return Err(ParseError { line, message: "unbalanced `)`".into() });
                    };
                    let value = match open.typed {
                        None => Value::List(open.items),
                        Some(name) => {
                            let mut items = open.items;
                            match (items.pop(), items.is_empty()) {
                                (Some(v), true) => Value::Typed(name, Box::new(v)),
                                _ => {
                                    return Err(ParseError {
                                        line,
                                        message: format!("typed parameter {name}(...) must hold exactly one value"),
                                    });
                                }
                            }
                        }
                    };
                    if stack.is_empty() {
                        return match value {
                            Value::List(items) => Ok(items),
                            _ => Err(ParseError { line, message: "unbalanced `)`".into() }),
                        };
                    }
                    value
                }
                Tok::Comma if state == State::AfterValue => {
                    state = State::AfterComma;
                    continue;
                }
                Tok::Open | Tok::Keyword(_) if state != State::AfterValue => {
                    let typed = match tok {
                        Tok::Keyword(name) => {
                            let (after, after_line) = self.next()?;
                            if after != Tok::Open {
                                return Err(unexpected(&after, after_line, &format!("`(` after {name}")));
                            }
                            Some(name)
                        }
                        _ => None,
                    };
                    if stack.len() >= MAX_NESTING {
                        return Err(ParseError {
                            line,
                            message: format!("parameter lists nested deeper than {MAX_NESTING} levels"),
                        });
                    }
                    stack.push(Open { items: Vec::new(), typed, line });
                    state = State::Start;
                    continue;
                }
                Tok::Eof => {
                    let open_line = stack.last().map_or(start_line, |o| o.line);
                    return Err(ParseError {
                        line,
                        message: format!("unexpected end of file in a parameter list opened at line {open_line}"),
                    });
                }
                _ if state == State::AfterValue => return Err(unexpected(&tok, line, "`,` or `)`")),
                Tok::Ref(n) => Value::Ref(n),
                Tok::Int(i) => Value::Integer(i),
                Tok::Real(r) => Value::Real(r),
                Tok::Str(s) => Value::String(s),
                Tok::Enum(e) => Value::Enum(e),
                Tok::Binary(b) => Value::Binary(b),
                Tok::Dollar => Value::Unset,
                Tok::Star => Value::Derived,
                other => return Err(unexpected(&other, line, "a parameter value")),
            };
            let Some(open) = stack.last_mut() else {
                return Err(ParseError { line, message: "value outside a parameter list".into() });
            };
            open.items.push(value);
            state = State::AfterValue;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wrap(data: &str) -> String {
        format!(
            "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('x'),'2;1');\nENDSEC;\nDATA;\n{data}\nENDSEC;\nEND-ISO-10303-21;\n"
        )
    }

    fn one(data: &str) -> Instance {
        let ex = parse(wrap(data).as_bytes()).expect("parses");
        assert_eq!(ex.order.len(), 1);
        ex.instances[&ex.order[0]].clone()
    }

    fn args(data: &str) -> Vec<Value> {
        match one(data).body {
            Body::Simple(r) => r.args,
            Body::Complex(_) => panic!("complex"),
        }
    }

    fn err(text: &str) -> ParseError {
        parse(text.as_bytes()).expect_err("must fail")
    }

    #[test]
    fn strings_unescape_doubled_quotes_and_span_lines() {
        let a = args("#1 = A('it''s','','a\nb','''');");
        assert_eq!(
            a,
            vec![
                Value::String("it's".into()),
                Value::String(String::new()),
                Value::String("a\nb".into()),
                Value::String("'".into())
            ]
        );
    }

    #[test]
    fn numbers_with_exponents_signs_and_bare_points() {
        let a = args("#1 = A(1.E-07,-0.,+2.5E+3,12,-7,1.5e2);");
        assert_eq!(a[0], Value::Real(1e-7));
        assert!(matches!(a[1], Value::Real(z) if z == 0.0 && z.is_sign_negative()));
        assert_eq!(a[2], Value::Real(2500.0));
        assert_eq!(a[3], Value::Integer(12));
        assert_eq!(a[4], Value::Integer(-7));
        assert_eq!(a[5], Value::Real(150.0));
    }

    #[test]
    fn enums_unset_derived_refs_binaries_and_typed_values() {
        let a = args("#1 = A(.T.,.milli.,$,*,#42,\"0FF\",LENGTH_MEASURE(25.4),(#1,(2,()),B(C(1))));");
        assert_eq!(a[0], Value::Enum("T".into()));
        assert_eq!(a[1], Value::Enum("MILLI".into()));
        assert_eq!(a[2], Value::Unset);
        assert_eq!(a[3], Value::Derived);
        assert_eq!(a[4], Value::Ref(42));
        assert_eq!(a[5], Value::Binary("0FF".into()));
        assert_eq!(a[6], Value::Typed("LENGTH_MEASURE".into(), Box::new(Value::Real(25.4))));
        let inner = Value::Typed("C".into(), Box::new(Value::Integer(1)));
        assert_eq!(
            a[7],
            Value::List(vec![
                Value::Ref(1),
                Value::List(vec![Value::Integer(2), Value::List(vec![])]),
                Value::Typed("B".into(), Box::new(inner)),
            ])
        );
    }

    #[test]
    fn complex_instances_keep_their_records_in_order() {
        let i = one("#7 = ( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) );");
        let Body::Complex(rs) = &i.body else { panic!("simple") };
        let names: Vec<&str> = rs.iter().map(|r| r.name.as_str()).collect();
        assert_eq!(names, ["LENGTH_UNIT", "NAMED_UNIT", "SI_UNIT"]);
        assert_eq!(
            i.record("SI_UNIT").map(|r| r.args.clone()),
            Some(vec![Value::Enum("MILLI".into()), Value::Enum("METRE".into())])
        );
        assert_eq!(i.type_name(), "(LENGTH_UNIT NAMED_UNIT SI_UNIT)");
    }

    #[test]
    fn comments_are_blank_and_lines_are_counted_through_them() {
        let ex = parse(wrap("/* one\ntwo */ #1 = A(/* in */ 1);\n#2 = B();").as_bytes()).expect("parses");
        assert_eq!(ex.order, [1, 2]);
        assert_eq!(ex.instances[&1].line, 7);
        assert_eq!(ex.instances[&2].line, 8);
    }

    #[test]
    fn several_data_sections_and_the_edition_3_data_parameters() {
        let text = "ISO-10303-21;HEADER;ENDSEC;DATA('a',('b'));#1=A();ENDSEC;DATA;#2=B();ENDSEC;END-ISO-10303-21;";
        let ex = parse(text.as_bytes()).expect("parses");
        assert_eq!(ex.order, [1, 2]);
    }

    #[test]
    fn nesting_is_capped_with_an_error_not_a_stack_overflow() {
        let deep = format!("#1 = A({}{});", "(".repeat(100_000), ")".repeat(100_000));
        let e = err(&wrap(&deep));
        assert!(e.message.contains("nested deeper"), "{e:?}");
        assert_eq!(e.line, 6);
        let ok = format!("#1 = A({}{});", "(".repeat(MAX_NESTING - 1), ")".repeat(MAX_NESTING - 1));
        assert!(parse(wrap(&ok).as_bytes()).is_ok());
    }

    #[test]
    fn truncated_input_is_an_error_with_a_line() {
        let full = wrap("#1 = A(1,\n(2,3),'x');");
        for cut in 0..full.len() - "END-ISO-10303-21;\n".len() {
            let e = parse(&full.as_bytes()[..cut]).expect_err("truncated must fail");
            assert!(e.line >= 1 && e.line <= 9, "{cut}: {e:?}");
        }
        let e = err(&wrap("#1 = A(1,\n(2,3)").replace("\nENDSEC;\nEND-ISO-10303-21;\n", ""));
        assert!(e.message.contains("end of file"), "{e:?}");
        assert_eq!(
            err(&wrap("#1 = A('abc);")).message,
            "instance #1: unterminated string (`'` without its closing `'`)"
        );
        assert!(err(&wrap("#1 = A(1); /* open")).message.contains("unterminated comment"));
    }

    #[test]
    fn malformed_parameters_are_errors_with_their_line() {
        for (data, what) in [
            ("#1 = A(1 2);", "`,` or `)`"),
            ("#1 = A(1,);", "a parameter value"),
            ("#1 = A(,1);", "a parameter value"),
            ("#1 = A(B);", "`(` after B"),
            ("#1 = A(B(1,2));", "exactly one value"),
            ("#1 = A(1.E);", "exponent"),
            ("#1 = A(#);", "instance number"),
            ("#1 = A(99999999999999999999);", "too large"),
            ("#1 = A(.T);", "enumeration"),
            ("#1 = A(1)", "`;`"),
            ("#1 = ( );", "entity name"),
            ("#1 = A(1);\n#1 = B();", "defined twice"),
            ("#1 = A(\u{1});", "0x01"),
        ] {
            let e = err(&wrap(data));
            assert!(e.message.contains(what), "{data}: {e:?}");
            assert!((6..=7).contains(&e.line), "{data}: {e:?}");
        }
    }

    #[test]
    fn header_and_envelope_errors() {
        assert!(err("").message.contains("ISO-10303-21"));
        assert!(err("ISO-10303-21;\nHEADER;\nENDSEC;\nEND-ISO-10303-21;").message.contains("no DATA"));
        assert_eq!(err("ISO-10303-21;\nHEADER;\nFOO(1 2);").line, 3);
        assert!(err("\u{ff}\u{fe}garbage").message.contains("unexpected byte"));
    }
}
