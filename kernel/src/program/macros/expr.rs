//! Expressions as each control's macro language evaluates them: Fanuc's
//! custom macro B (`[#1+2.]`, `SIN[#3]`, `#[#1]`, `EQ`..`LE`), LinuxCNC's
//! rs274ngc (`[#1 * 2]`, `#<depth>`, `**`, `ATAN[y]/[x]`) and Sinumerik's
//! arithmetic (`R1*2+SIN(30)`, `ATAN2(y,x)`, `==`..`>=`).
//!
//! Evaluated as it is parsed (a recursive descent over the text, no tree):
//! an expression has no side effects, and a loop's condition is read again
//! on each turn. Angles are degrees, as on every control. The operators'
//! precedence is each language's own, from its manual:
//!
//! - Fanuc: functions, then `* / AND MOD`, then `+ - OR XOR`, then the
//!   comparisons; `AND OR XOR` bitwise on whole numbers (on 0 and 1, the
//!   logic of a condition).
//! - rs274ngc: `**`, then `* / MOD`, then `+ -`, then the comparisons, then
//!   `AND OR XOR` (logic: not 0 is true).
//! - Sinumerik: `NOT`, then `* / DIV MOD`, then `+ -`, then `AND`, `XOR`,
//!   `OR`, then the comparisons last (`R1>5 AND R2<3` reads `R1>(5 AND
//!   R2)<3`: the manual says to bracket each comparison, and so does the
//!   control).
//!
//! Written here rather than taken from a crate: no crate reads a CNC
//! control's macro language, and an expression parser for a general
//! language (evalexpr, meval) has other operators, other precedence and no
//! vacant value; a reading that differs from the control's in one
//! operator is the hazard this reader exists to refuse.

use super::Language;
use crate::math::Real;

/// A value as the language holds it: `None` is Fanuc's vacant (`#0`, a
/// variable never set), which is not zero (a word given a vacant value is
/// dropped, `EQ #0` tells it); the other languages have none.
pub type Value = Option<Real>;

/// Where an expression's variables are read: the reader's store.
pub trait Lookup {
    /// Fanuc's `#n`, LinuxCNC's numbered `#n`.
    ///
    /// # Failures
    /// A variable the verification cannot know (a system variable, one the
    /// control keeps between programs), named.
    fn number(&self, n: Real) -> Result<Value, String>;
    /// LinuxCNC's `#<name>`, Sinumerik's local variable (`DEF REAL DEPTH`).
    ///
    /// # Failures
    /// One not defined.
    fn named(&self, name: &str) -> Result<Value, String>;
    /// Sinumerik's `R` parameter `Rn`.
    ///
    /// # Failures
    /// One not set in the program (the control keeps R parameters).
    fn r(&self, n: Real) -> Result<Value, String>;
    /// Whether LinuxCNC's `#<name>` exists (`EXISTS[#<name>]`).
    fn exists(&self, name: &str) -> bool;
}

/// The deepest nesting of brackets an expression may have: Fanuc allows
/// five levels; the bound keeps the parser's recursion small.
pub const MAX_DEPTH: usize = 32;

/// An expression's text being evaluated.
pub struct Parser<'t, 'l> {
    lang: Language,
    text: &'t [u8],
    /// The next byte to read.
    pub at: usize,
    vars: &'l dyn Lookup,
    depth: usize,
}

/// The value of the expression `text` (all of it) in `lang`.
///
/// # Failures
/// The text not an expression of the language (named with where it
/// stops), a variable the verification cannot know, a function's domain
/// (`SQRT` of a negative, a division by 0), a result not finite.
pub fn evaluate(lang: Language, text: &str, vars: &dyn Lookup) -> Result<Value, String> {
    let mut p = Parser::new(lang, text, vars);
    let v = p.expression()?;
    p.skip_spaces();
    if p.at < p.text.len() {
        return Err(p.unexpected());
    }
    Ok(v)
}

/// A number as a condition: true where not 0 (a vacant value is false).
pub fn truth(v: Value) -> bool {
    v.is_some_and(|v| v != 0.0)
}

fn boolean(b: bool) -> Value {
    Some(if b { 1.0 } else { 0.0 })
}

/// Fanuc reads a vacant value as 0 in arithmetic.
fn num(v: Value) -> Real {
    v.unwrap_or(0.0)
}

/// A binary operator.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Op {
    Add,
    Sub,
    Mul,
    Div,
    IntDiv,
    Mod,
    Pow,
    And,
    Or,
    Xor,
    Eq,
    Ne,
    Gt,
    Ge,
    Lt,
    Le,
}

impl<'t, 'l> Parser<'t, 'l> {
    /// A parser of `text` in `lang`, its variables read from `vars`.
    pub fn new(lang: Language, text: &'t str, vars: &'l dyn Lookup) -> Self {
        Self {
            lang,
            text: text.as_bytes(),
            at: 0,
            vars,
            depth: 0,
        }
    }

    /// The byte at the parser, if any.
    pub fn byte(&self) -> Option<u8> {
        self.text.get(self.at).copied()
    }

    /// One operand (no sign before it): a number, a variable, a bracketed
    /// expression or a function.
    ///
    /// # Failures
    /// As [`evaluate`].
    pub fn operand_value(&mut self) -> Result<Value, String> {
        self.operand()
    }

    /// A name at the parser (letters, digits, `_`), upper-cased.
    pub fn identifier(&mut self) -> String {
        self.name()
    }

    /// The text from where the parser stands, for a message.
    fn rest(&self) -> String {
        let s = String::from_utf8_lossy(&self.text[self.at..]);
        crate::files::excerpt(s.trim()).to_string()
    }

    fn unexpected(&self) -> String {
        if self.at >= self.text.len() {
            "the expression ends where a value is wanted".into()
        } else {
            format!("'{}' where the expression should go on", self.rest())
        }
    }

    /// Spaces are nothing in an expression (Fanuc and rs274ngc drop them
    /// from a block; Sinumerik's expressions may hold them).
    pub fn skip_spaces(&mut self) {
        while self
            .text
            .get(self.at)
            .is_some_and(|b| *b == b' ' || *b == b'\t')
        {
            self.at += 1;
        }
    }

    fn peek(&mut self) -> Option<u8> {
        self.skip_spaces();
        self.text.get(self.at).copied()
    }

    /// Whether the text goes on with the keyword `k` (letters, as a whole
    /// word where letters follow in Sinumerik's identifiers), consuming it.
    fn keyword(&mut self, k: &str) -> bool {
        self.skip_spaces();
        let end = self.at + k.len();
        if self.text.len() < end || !self.text[self.at..end].eq_ignore_ascii_case(k.as_bytes()) {
            return false;
        }
        // Sinumerik's names run on in letters, digits and `_`: `ANDY` is a
        // name, not `AND Y`. Fanuc and rs274ngc drop spaces, so `ANDX` can
        // only be `AND X` there... but no operand begins with a letter but a
        // function, which is a whole keyword of its own.
        if self.lang == Language::Sinumerik
            && self
                .text
                .get(end)
                .is_some_and(|b| b.is_ascii_alphanumeric() || *b == b'_')
            && k.bytes().all(|b| b.is_ascii_alphabetic())
        {
            return false;
        }
        self.at = end;
        true
    }

    fn symbol(&mut self, s: &str) -> bool {
        self.skip_spaces();
        if self.text[self.at..].starts_with(s.as_bytes()) {
            self.at += s.len();
            true
        } else {
            false
        }
    }

    fn open(&self) -> u8 {
        if self.lang == Language::Sinumerik {
            b'('
        } else {
            b'['
        }
    }

    fn close(&self) -> u8 {
        if self.lang == Language::Sinumerik {
            b')'
        } else {
            b']'
        }
    }

    /// A whole expression.
    ///
    /// # Failures
    /// As [`evaluate`].
    pub fn expression(&mut self) -> Result<Value, String> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(format!(
                "brackets nested deeper than {MAX_DEPTH} levels in an expression"
            ));
        }
        let v = match self.lang {
            Language::Fanuc => self.comparison(Self::fanuc_sum),
            Language::Rs274 => self.rs274_logic(),
            Language::Sinumerik => self.comparison(Self::sinumerik_or),
        };
        self.depth -= 1;
        v
    }

    /// The comparison operator at the parser, if there is one (consumed).
    fn comparison_op(&mut self) -> Option<Op> {
        let ops: &[(&str, Op)] = match self.lang {
            Language::Sinumerik => &[
                ("==", Op::Eq),
                ("<>", Op::Ne),
                (">=", Op::Ge),
                ("<=", Op::Le),
                (">", Op::Gt),
                ("<", Op::Lt),
            ],
            _ => &[
                ("EQ", Op::Eq),
                ("NE", Op::Ne),
                ("GT", Op::Gt),
                ("GE", Op::Ge),
                ("LT", Op::Lt),
                ("LE", Op::Le),
            ],
        };
        for (s, op) in ops {
            let hit = if s.as_bytes()[0].is_ascii_alphabetic() {
                self.keyword(s)
            } else {
                self.symbol(s)
            };
            if hit {
                return Some(*op);
            }
        }
        None
    }

    /// Comparisons over the operands `next` reads (left to right).
    fn comparison(
        &mut self,
        next: fn(&mut Self) -> Result<Value, String>,
    ) -> Result<Value, String> {
        let mut v = next(self)?;
        while let Some(op) = self.comparison_op() {
            let w = next(self)?;
            v = self.apply(op, v, w)?;
        }
        Ok(v)
    }

    /// Operands `next` reads, joined left to right by the operators `ops`
    /// (a symbol, or a keyword where it is letters).
    fn level(
        &mut self,
        ops: &[(&str, Op)],
        next: fn(&mut Self) -> Result<Value, String>,
    ) -> Result<Value, String> {
        let mut v = next(self)?;
        'more: loop {
            self.skip_spaces();
            for (s, op) in ops {
                let hit = if s.as_bytes()[0].is_ascii_alphabetic() {
                    self.keyword(s)
                } else {
                    // rs274ngc's `**` is a power, never a product's `*`.
                    !(*s == "*" && self.text[self.at..].starts_with(b"**")) && self.symbol(s)
                };
                if hit {
                    let w = next(self)?;
                    v = self.apply(*op, v, w)?;
                    continue 'more;
                }
            }
            return Ok(v);
        }
    }

    fn fanuc_sum(&mut self) -> Result<Value, String> {
        const OPS: [(&str, Op); 4] = [
            ("+", Op::Add),
            ("-", Op::Sub),
            ("OR", Op::Or),
            ("XOR", Op::Xor),
        ];
        self.level(&OPS, Self::fanuc_product)
    }

    fn fanuc_product(&mut self) -> Result<Value, String> {
        const OPS: [(&str, Op); 4] = [
            ("*", Op::Mul),
            ("/", Op::Div),
            ("AND", Op::And),
            ("MOD", Op::Mod),
        ];
        self.level(&OPS, Self::unary)
    }

    fn rs274_logic(&mut self) -> Result<Value, String> {
        const OPS: [(&str, Op); 3] = [("AND", Op::And), ("XOR", Op::Xor), ("OR", Op::Or)];
        self.level(&OPS, |p| p.comparison(Self::rs274_sum))
    }

    fn rs274_sum(&mut self) -> Result<Value, String> {
        self.level(&[("+", Op::Add), ("-", Op::Sub)], Self::rs274_product)
    }

    fn rs274_product(&mut self) -> Result<Value, String> {
        const OPS: [(&str, Op); 3] = [("*", Op::Mul), ("/", Op::Div), ("MOD", Op::Mod)];
        self.level(&OPS, Self::rs274_power)
    }

    fn rs274_power(&mut self) -> Result<Value, String> {
        self.level(&[("**", Op::Pow)], Self::unary)
    }

    fn sinumerik_or(&mut self) -> Result<Value, String> {
        self.level(&[("OR", Op::Or)], Self::sinumerik_xor)
    }

    fn sinumerik_xor(&mut self) -> Result<Value, String> {
        self.level(&[("XOR", Op::Xor)], Self::sinumerik_and)
    }

    fn sinumerik_and(&mut self) -> Result<Value, String> {
        self.level(&[("AND", Op::And)], Self::sinumerik_sum)
    }

    fn sinumerik_sum(&mut self) -> Result<Value, String> {
        self.level(&[("+", Op::Add), ("-", Op::Sub)], Self::sinumerik_product)
    }

    fn sinumerik_product(&mut self) -> Result<Value, String> {
        const OPS: [(&str, Op); 4] = [
            ("*", Op::Mul),
            ("/", Op::Div),
            ("DIV", Op::IntDiv),
            ("MOD", Op::Mod),
        ];
        self.level(&OPS, Self::unary)
    }

    /// A sign, Sinumerik's `NOT`, then an operand.
    fn unary(&mut self) -> Result<Value, String> {
        if self.symbol("-") {
            return Ok(Some(-num(self.unary()?)));
        }
        if self.symbol("+") {
            return Ok(Some(num(self.unary()?)));
        }
        if self.lang == Language::Sinumerik && self.keyword("NOT") {
            return Ok(boolean(!truth(self.unary()?)));
        }
        self.operand()
    }

    /// A number, a variable, a bracketed expression or a function.
    fn operand(&mut self) -> Result<Value, String> {
        let Some(c) = self.peek() else {
            return Err(self.unexpected());
        };
        if c.is_ascii_digit() || c == b'.' {
            return self.number().map(Some);
        }
        if c == self.open() {
            self.at += 1;
            let v = self.expression()?;
            self.expect_close()?;
            return Ok(v);
        }
        if c == b'#' && self.lang != Language::Sinumerik {
            return self.variable();
        }
        if c == b'$' {
            return Err(format!(
                "'{}': a system variable, whose value is the control's, which the verification does not know",
                self.rest()
            ));
        }
        if c.is_ascii_alphabetic() {
            return self.named_operand();
        }
        Err(self.unexpected())
    }

    fn expect_close(&mut self) -> Result<(), String> {
        if self.peek() == Some(self.close()) {
            self.at += 1;
            Ok(())
        } else {
            Err(format!(
                "a '{}' that is not closed: {}",
                self.open() as char,
                self.unexpected()
            ))
        }
    }

    /// A number as written: digits with at most one point.
    pub fn number(&mut self) -> Result<Real, String> {
        self.skip_spaces();
        let from = self.at;
        let mut points = 0;
        while let Some(b) = self.text.get(self.at) {
            match b {
                b'0'..=b'9' => {}
                b'.' => points += 1,
                _ => break,
            }
            self.at += 1;
        }
        let s = std::str::from_utf8(&self.text[from..self.at]).unwrap_or_default();
        if points > 1 || s == "." || s.is_empty() {
            return Err(format!("'{s}' is not a number"));
        }
        if s.len() > crate::program::words::MAX_NUMBER {
            return Err(format!(
                "a number longer than {} characters",
                crate::program::words::MAX_NUMBER
            ));
        }
        s.parse().map_err(|_| format!("'{s}' is not a number"))
    }

    /// `#n`, `#[expr]`, `##n` (rs274ngc), `#<name>` (rs274ngc).
    fn variable(&mut self) -> Result<Value, String> {
        self.at += 1; // '#'
        match self.peek() {
            Some(b'<') if self.lang == Language::Rs274 => {
                let name = self.angle_name()?;
                self.vars.named(&name)
            }
            Some(b'[') => {
                self.at += 1;
                let n = self.expression()?;
                self.expect_close()?;
                self.vars.number(self.index(n)?)
            }
            Some(b'#') if self.lang == Language::Rs274 => {
                let n = self.variable()?;
                self.vars.number(self.index(n)?)
            }
            Some(c) if c.is_ascii_digit() => {
                let n = self.number()?;
                self.vars.number(self.index(Some(n))?)
            }
            _ => Err(format!(
                "'#' without a variable's number: {}",
                self.unexpected()
            )),
        }
    }

    /// A variable's number: a whole number.
    fn index(&self, n: Value) -> Result<Real, String> {
        match n {
            Some(n) if n >= 0.0 && n.fract() == 0.0 && n < 1e9 => Ok(n),
            Some(n) => Err(format!(
                "#{n}: a variable's number is a whole number from 0"
            )),
            None => Err("#<vacant>: a variable's number that is vacant".into()),
        }
    }

    /// rs274ngc's `<name>` after `#`: letters, digits, `_`, spaces
    /// dropped, case folded.
    pub fn angle_name(&mut self) -> Result<String, String> {
        self.skip_spaces();
        self.at += 1; // '<'
        let from = self.at;
        while self.text.get(self.at).is_some_and(|b| *b != b'>') {
            self.at += 1;
        }
        if self.at >= self.text.len() {
            return Err("a parameter's name '<' not closed by '>'".into());
        }
        let raw = std::str::from_utf8(&self.text[from..self.at]).unwrap_or_default();
        self.at += 1;
        let name: String = raw
            .chars()
            .filter(|c| !c.is_whitespace())
            .map(|c| c.to_ascii_lowercase())
            .collect();
        if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            return Err(format!(
                "#<{raw}>: a parameter's name is letters, digits and '_'"
            ));
        }
        Ok(name)
    }

    /// The letters and digits (and `_`) of a name at the parser.
    fn name(&mut self) -> String {
        self.skip_spaces();
        let from = self.at;
        while self
            .text
            .get(self.at)
            .is_some_and(|b| b.is_ascii_alphanumeric() || *b == b'_')
        {
            self.at += 1;
        }
        String::from_utf8_lossy(&self.text[from..self.at]).to_ascii_uppercase()
    }

    /// A function, Sinumerik's `R` parameter or local variable, or the
    /// constants `TRUE`/`FALSE`.
    fn named_operand(&mut self) -> Result<Value, String> {
        let from = self.at;
        if self.lang == Language::Sinumerik {
            let name = self.name();
            if let Some(n) = r_number(&name) {
                return self.vars.r(n);
            }
            if name == "R" && self.peek() == Some(b'[') {
                self.at += 1;
                let n = self.expression()?;
                self.at = self.at.min(self.text.len());
                if self.peek() != Some(b']') {
                    return Err("R[ not closed by ']'".into());
                }
                self.at += 1;
                return self.vars.r(self.index(n)?);
            }
            match name.as_str() {
                "TRUE" => return Ok(Some(1.0)),
                "FALSE" => return Ok(Some(0.0)),
                _ => {}
            }
            if self.peek() == Some(b'(') {
                return self.function(&name);
            }
            return self.vars.named(&name);
        }
        // Fanuc and rs274ngc: a function's name, then its bracket.
        while self.text.get(self.at).is_some_and(u8::is_ascii_alphabetic) {
            self.at += 1;
        }
        let name = String::from_utf8_lossy(&self.text[from..self.at]).to_ascii_uppercase();
        if self.peek() != Some(b'[') {
            self.at = from;
            return Err(self.unexpected());
        }
        self.function(&name)
    }

    /// The arguments of a function in brackets, separated by `,`.
    fn arguments(&mut self) -> Result<Vec<Value>, String> {
        self.at += 1; // the open bracket
        let mut out = vec![self.expression()?];
        while self.symbol(",") {
            out.push(self.expression()?);
        }
        self.expect_close()?;
        Ok(out)
    }

    /// Function `name`, its arguments at the parser.
    fn function(&mut self, name: &str) -> Result<Value, String> {
        let lang = self.lang;
        if lang == Language::Rs274 && name == "EXISTS" {
            self.at += 1;
            if !self.symbol("#") || self.peek() != Some(b'<') {
                return Err("EXISTS takes a named parameter, #<name>".into());
            }
            let n = self.angle_name()?;
            let known = self.vars.exists(&n);
            self.expect_close()?;
            return Ok(boolean(known));
        }
        let known: &[&str] = match lang {
            Language::Fanuc => &[
                "SIN", "COS", "TAN", "ASIN", "ACOS", "ATAN", "SQRT", "SQR", "ABS", "ROUND", "RND",
                "FIX", "FUP", "LN", "EXP", "POW",
            ],
            Language::Rs274 => &[
                "SIN", "COS", "TAN", "ASIN", "ACOS", "ATAN", "SQRT", "ABS", "ROUND", "FIX", "FUP",
                "LN", "EXP",
            ],
            Language::Sinumerik => &[
                "SIN", "COS", "TAN", "ASIN", "ACOS", "ATAN2", "SQRT", "ABS", "ROUND", "TRUNC",
                "POT", "LN", "EXP", "MINVAL", "MAXVAL",
            ],
        };
        if !known.contains(&name) {
            return Err(format!(
                "{name}: not a function the verification evaluates in {} (it reads {})",
                lang.name(),
                known.join(" ")
            ));
        }
        let mut args = self.arguments()?;
        // Fanuc's and rs274ngc's ATAN[y]/[x].
        if name == "ATAN" && args.len() == 1 {
            if !self.symbol("/") || self.peek() != Some(b'[') {
                return Err("ATAN takes two values: ATAN[y]/[x]".into());
            }
            self.at += 1;
            let x = self.expression()?;
            self.expect_close()?;
            args.push(x);
        }
        let two = matches!(name, "ATAN" | "ATAN2" | "POW" | "MINVAL" | "MAXVAL");
        let want = if two { 2 } else { 1 };
        if args.len() != want {
            return Err(format!(
                "{name} takes {want} value{}, not {}",
                if want == 1 { "" } else { "s" },
                args.len()
            ));
        }
        let a = num(args[0]);
        let b = args.get(1).copied().map(num).unwrap_or(0.0);
        let deg = Real::to_degrees;
        let v = match name {
            "SIN" => a.to_radians().sin(),
            "COS" => a.to_radians().cos(),
            "TAN" => {
                let c = a.to_radians().cos();
                if c.abs() < crate::tolerance::ROUNDING {
                    return Err(format!("TAN of {a} degrees is infinite"));
                }
                a.to_radians().tan()
            }
            "ASIN" | "ACOS" => {
                if !(-1.0..=1.0).contains(&a) {
                    return Err(format!("{name} of {a}, outside -1 to 1"));
                }
                let v = if name == "ASIN" {
                    deg(a.asin())
                } else {
                    deg(a.acos())
                };
                // Fanuc (parameter NAT, 6004#0, as the control leaves the
                // factory): ASIN gives 270 to 90 degrees.
                if lang == Language::Fanuc && v < 0.0 {
                    v + 360.0
                } else {
                    v
                }
            }
            "ATAN" | "ATAN2" => {
                if a == 0.0 && b == 0.0 {
                    return Err(format!("{name} of 0 and 0 has no angle"));
                }
                let v = deg(a.atan2(b));
                // Fanuc (NAT = 0): 0 to 360 degrees.
                if lang == Language::Fanuc && v < 0.0 {
                    v + 360.0
                } else {
                    v
                }
            }
            "SQRT" | "SQR" => {
                if a < 0.0 {
                    return Err(format!("{name} of {a}, a negative number"));
                }
                a.sqrt()
            }
            "ABS" => a.abs(),
            "ROUND" | "RND" => a.round(),
            // Fanuc's FIX drops the fraction, its FUP raises it (both away
            // from and towards 0); rs274ngc's round down and up.
            "FIX" if lang == Language::Fanuc => a.trunc(),
            "FUP" if lang == Language::Fanuc => {
                if a.fract() == 0.0 {
                    a
                } else {
                    a.trunc() + a.signum()
                }
            }
            "FIX" => a.floor(),
            "FUP" => a.ceil(),
            "TRUNC" => a.trunc(),
            "LN" => {
                if !(a > 0.0) {
                    return Err(format!("LN of {a}, not above 0"));
                }
                a.ln()
            }
            "EXP" => a.exp(),
            "POT" => a * a,
            "POW" => a.powf(b),
            "MINVAL" => a.min(b),
            "MAXVAL" => a.max(b),
            _ => return Err(format!("{name}: not a function")),
        };
        finite(v, name)
    }

    /// `v op w` as the language computes it.
    fn apply(&self, op: Op, v: Value, w: Value) -> Result<Value, String> {
        let (a, b) = (num(v), num(w));
        let whole = |x: Real| -> Result<i64, String> {
            if x.fract() == 0.0 && x.abs() < 9e15 {
                Ok(x as i64)
            } else {
                Err(format!(
                    "{x}: AND, OR and XOR take whole numbers on {}",
                    self.lang.name()
                ))
            }
        };
        let logic = self.lang != Language::Fanuc;
        let r = match op {
            Op::Add => a + b,
            Op::Sub => a - b,
            Op::Mul => a * b,
            Op::Div | Op::IntDiv | Op::Mod if b == 0.0 => {
                return Err(format!("{a} divided by 0"));
            }
            Op::Div => a / b,
            Op::IntDiv => (a / b).trunc(),
            // rs274ngc's MOD is never negative; Fanuc's and Sinumerik's take
            // the sign of the dividend.
            Op::Mod if self.lang == Language::Rs274 => a.rem_euclid(b),
            Op::Mod => a % b,
            Op::Pow => a.powf(b),
            Op::And if logic => return Ok(boolean(truth(v) && truth(w))),
            Op::Or if logic => return Ok(boolean(truth(v) || truth(w))),
            Op::Xor if logic => return Ok(boolean(truth(v) != truth(w))),
            Op::And => (whole(a)? & whole(b)?) as Real,
            Op::Or => (whole(a)? | whole(b)?) as Real,
            Op::Xor => (whole(a)? ^ whole(b)?) as Real,
            // Fanuc: a vacant value equals only a vacant one; in the
            // order comparisons it is 0.
            Op::Eq => return Ok(boolean(v == w)),
            Op::Ne => return Ok(boolean(v != w)),
            Op::Gt => return Ok(boolean(a > b)),
            Op::Ge => return Ok(boolean(a >= b)),
            Op::Lt => return Ok(boolean(a < b)),
            Op::Le => return Ok(boolean(a <= b)),
        };
        finite(r, "the arithmetic")
    }
}

/// A result that is a number.
fn finite(v: Real, what: &str) -> Result<Value, String> {
    if v.is_finite() {
        Ok(Some(v))
    } else {
        Err(format!("{what} gives {v}, not a finite number"))
    }
}

/// Sinumerik's `R<digits>` as the parameter's number.
pub fn r_number(name: &str) -> Option<Real> {
    let digits = name.strip_prefix('R')?;
    (!digits.is_empty() && digits.len() <= 4 && digits.bytes().all(|b| b.is_ascii_digit()))
        .then(|| digits.parse().ok())
        .flatten()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    #[derive(Default)]
    struct Store {
        n: BTreeMap<u64, Real>,
        named: BTreeMap<String, Real>,
    }

    impl Lookup for Store {
        fn number(&self, n: Real) -> Result<Value, String> {
            Ok(self.n.get(&(n as u64)).copied())
        }
        fn named(&self, name: &str) -> Result<Value, String> {
            self.named
                .get(name)
                .copied()
                .map(Some)
                .ok_or_else(|| format!("{name} not defined"))
        }
        fn r(&self, n: Real) -> Result<Value, String> {
            self.number(n)
        }
        fn exists(&self, name: &str) -> bool {
            self.named.contains_key(name)
        }
    }

    fn store() -> Store {
        let mut s = Store::default();
        s.n.insert(1, 10.0);
        s.n.insert(2, 3.0);
        s.named.insert("depth".into(), 2.5);
        s.named.insert("DEPTH".into(), 2.5);
        s
    }

    fn eval(lang: Language, t: &str) -> Value {
        evaluate(lang, t, &store()).unwrap_or_else(|e| panic!("{t}: {e}"))
    }

    #[test]
    fn each_language_has_its_precedence() {
        use Language::*;
        assert_eq!(eval(Fanuc, "#1+#2*2"), Some(16.0));
        assert_eq!(eval(Fanuc, "[#1+#2]*2"), Some(26.0));
        assert_eq!(eval(Fanuc, "#1 GT 5"), Some(1.0));
        assert_eq!(eval(Fanuc, "SQRT[#1*#1]"), Some(10.0));
        assert_eq!(eval(Fanuc, "ATAN[1]/[-1]"), Some(135.0));
        assert_eq!(eval(Fanuc, "ATAN[-1]/[1]"), Some(315.0));
        assert_eq!(eval(Fanuc, "FIX[-1.5]"), Some(-1.0));
        assert_eq!(eval(Fanuc, "FUP[-1.5]"), Some(-2.0));
        assert_eq!(eval(Fanuc, "3 AND 5"), Some(1.0));
        assert_eq!(eval(Rs274, "[2 ** 3 * 2]"), Some(16.0));
        assert_eq!(eval(Rs274, "2 + 3 GT 4 AND 1"), Some(1.0));
        assert_eq!(eval(Rs274, "FIX[-1.5]"), Some(-2.0));
        assert_eq!(eval(Rs274, "-7 MOD 3"), Some(2.0));
        assert_eq!(eval(Rs274, "#<depth> * 2"), Some(5.0));
        assert_eq!(eval(Rs274, "EXISTS[#<depth>] + EXISTS[#<none>]"), Some(1.0));
        assert_eq!(eval(Rs274, "ATAN[1]/[-1]"), Some(135.0));
        assert_eq!(eval(Sinumerik, "R1+R2*2"), Some(16.0));
        assert_eq!(eval(Sinumerik, "(R1+R2)*2"), Some(26.0));
        assert_eq!(eval(Sinumerik, "7 DIV 2 + 7 MOD 2"), Some(4.0));
        assert_eq!(eval(Sinumerik, "POT(3) + DEPTH"), Some(11.5));
        // The comparisons come last: 1 > (5 AND 0) is true.
        assert_eq!(eval(Sinumerik, "1 > 5 AND 0"), Some(1.0));
        assert_eq!(eval(Sinumerik, "(1 > 5) AND (0 == 0)"), Some(0.0));
        assert_eq!(eval(Sinumerik, "ATAN2(1, -1)"), Some(135.0));
    }

    #[test]
    fn a_vacant_value_is_not_zero() {
        use Language::Fanuc;
        assert_eq!(eval(Fanuc, "#5"), None);
        assert_eq!(eval(Fanuc, "#5 EQ #0"), Some(1.0));
        assert_eq!(eval(Fanuc, "#5 EQ 0"), Some(0.0));
        assert_eq!(eval(Fanuc, "#5 + 0"), Some(0.0));
        assert_eq!(eval(Fanuc, "#5 GE 0"), Some(1.0));
        assert_eq!(eval(Fanuc, "#[#2-2]"), Some(10.0));
    }

    #[test]
    fn what_the_control_would_alarm_on_is_refused() {
        use Language::*;
        for (lang, t, says) in [
            (Fanuc, "#1/0", "divided by 0"),
            (Fanuc, "SQRT[-1]", "negative"),
            (Fanuc, "BIN[3]", "not a function"),
            (Fanuc, "[1+2", "not closed"),
            (Fanuc, "1.2.3", "not a number"),
            (Rs274, "#<nope>", "not defined"),
            (Rs274, "#<a b", "not closed"),
            (Sinumerik, "$AA_IM[X]", "system variable"),
            (Sinumerik, "ACOS(2)", "outside"),
            (Sinumerik, "1 +", "ends"),
            (Fanuc, "ATAN[0]/[0]", "no angle"),
        ] {
            let e = evaluate(lang, t, &store()).unwrap_err();
            assert!(e.contains(says), "{t}: {e}");
        }
        let deep = format!("{}1{}", "[".repeat(40), "]".repeat(40));
        assert!(evaluate(Fanuc, &deep, &store())
            .unwrap_err()
            .contains("nested"));
    }
}
