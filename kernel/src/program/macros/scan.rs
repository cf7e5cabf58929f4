//! A file's landmarks, found once before it is read: its block numbers
//! and labels (where a jump lands), the programs it holds (Fanuc's `O`
//! numbers), rs274ngc's subroutines, and each structured statement's
//! partner (a `WHILE`'s `END`, an `IF`'s `ELSE` and `ENDIF`), so that a
//! jump or a loop's turn is one look-up.

use super::Language;
use std::collections::BTreeMap;

/// A line's code split: its block number, its label (Sinumerik's
/// `MARK1:`), and the rest.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Parts<'c> {
    /// `N` and its number, where the line opens with one.
    pub number: Option<u32>,
    /// Sinumerik's label.
    pub label: Option<&'c str>,
    /// The rest of the code, trimmed.
    pub rest: &'c str,
}

/// `code` split into its number, label and rest.
pub fn parts(lang: Language, code: &str) -> Parts<'_> {
    let mut rest = code.trim_start();
    let mut number = None;
    let b = rest.as_bytes();
    if b.first()
        .is_some_and(|c| *c == b'N' || (lang == Language::Rs274 && *c == b'n'))
    {
        let digits = b[1..].iter().take_while(|c| c.is_ascii_digit()).count();
        if digits > 0 && digits <= 9 {
            number = rest[1..=digits].parse().ok();
            rest = rest[1 + digits..].trim_start();
        }
    }
    let mut label = None;
    if lang == Language::Sinumerik {
        let name_len = rest
            .bytes()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == b'_')
            .count();
        if name_len >= 2
            && rest.as_bytes()[0].is_ascii_alphabetic()
            && rest.as_bytes().get(name_len) == Some(&b':')
        {
            label = Some(&rest[..name_len]);
            rest = rest[name_len + 1..].trim_start();
        }
    }
    Parts {
        number,
        label,
        rest: rest.trim_end(),
    }
}

/// rs274ngc's o-word keywords.
pub const O_WORDS: [&str; 15] = [
    "SUB",
    "ENDSUB",
    "RETURN",
    "CALL",
    "IF",
    "ELSEIF",
    "ELSE",
    "ENDIF",
    "WHILE",
    "ENDWHILE",
    "DO",
    "REPEAT",
    "ENDREPEAT",
    "BREAK",
    "CONTINUE",
];

/// Sinumerik's structured statements.
pub const SINUMERIK_BLOCKS: [&str; 11] = [
    "IF", "ELSE", "ENDIF", "WHILE", "ENDWHILE", "LOOP", "ENDLOOP", "FOR", "ENDFOR", "REPEAT",
    "UNTIL",
];

/// What a line is to the file's structure.
#[derive(Debug, Clone, PartialEq)]
pub enum Key {
    /// Nothing structural.
    Plain,
    /// Fanuc's `WHILE [..] DO m`.
    While(u32),
    /// Fanuc's `DO m` alone (a loop without end).
    Do(u32),
    /// Fanuc's `END m`.
    End(u32),
    /// Fanuc's `O` number: a program begins.
    Program(u32),
    /// One of Sinumerik's structured statements.
    Sinumerik(&'static str),
    /// An rs274ngc o-word: its name (`100`, `<name>` folded) and keyword.
    O(String, &'static str),
}

/// The spaces of `s` dropped (Fanuc and rs274ngc read a block so).
pub fn squeezed(s: &str) -> String {
    s.chars().filter(|c| !c.is_whitespace()).collect()
}

/// What line `code` is to its file's structure, in `lang`.
pub fn key(lang: Language, code: &str) -> Key {
    let p = parts(lang, code);
    match lang {
        Language::Fanuc => {
            let s = p.rest.as_bytes();
            let digits_after = |k: usize| -> Option<u32> {
                let d: String = p.rest[k..].chars().filter(|c| !c.is_whitespace()).collect();
                (!d.is_empty() && d.len() <= 4 && d.bytes().all(|b| b.is_ascii_digit()))
                    .then(|| d.parse().ok())
                    .flatten()
            };
            if p.rest.starts_with("WHILE") {
                let sq = squeezed(p.rest);
                return match sq.rfind("DO") {
                    Some(i) => sq[i + 2..].parse().map_or(Key::Plain, Key::While),
                    None => Key::Plain,
                };
            }
            if p.rest.starts_with("DO") {
                return digits_after(2).map_or(Key::Plain, Key::Do);
            }
            if p.rest.starts_with("END") {
                return digits_after(3).map_or(Key::Plain, Key::End);
            }
            if s.first() == Some(&b'O') && s.len() > 1 && s[1].is_ascii_digit() {
                let d: String = p.rest[1..]
                    .chars()
                    .take_while(char::is_ascii_digit)
                    .collect();
                return d.parse().map_or(Key::Plain, Key::Program);
            }
            Key::Plain
        }
        Language::Sinumerik => {
            let first = p.rest.split_whitespace().next().unwrap_or("");
            let upper = first.to_ascii_uppercase();
            match SINUMERIK_BLOCKS.iter().find(|k| **k == upper) {
                // `IF .. GOTOF` is a jump, not a block; `REPEAT MARK` a
                // section's repetition.
                Some(&"IF") if has_goto(p.rest) => Key::Plain,
                Some(&"REPEAT") if p.rest.split_whitespace().nth(1).is_some() => Key::Plain,
                Some(k) => Key::Sinumerik(k),
                None => Key::Plain,
            }
        }
        Language::Rs274 => {
            if !p.rest.starts_with(['O', 'o']) {
                return Key::Plain;
            }
            let sq = squeezed(p.rest).to_ascii_uppercase();
            let Some(name_and_rest) = sq.strip_prefix('O') else {
                return Key::Plain;
            };
            let (name, rest) = if let Some(r) = name_and_rest.strip_prefix('<') {
                match r.find('>') {
                    Some(e) => (format!("<{}>", &r[..e]), &r[e + 1..]),
                    None => return Key::Plain,
                }
            } else {
                let d = name_and_rest.bytes().take_while(u8::is_ascii_digit).count();
                if d == 0 {
                    return Key::Plain;
                }
                (
                    name_and_rest[..d].trim_start_matches('0').to_owned(),
                    &name_and_rest[d..],
                )
            };
            // The longest keyword the rest opens with (ENDSUB before END..).
            let mut best: Option<&'static str> = None;
            for k in O_WORDS {
                if rest.starts_with(k) && best.is_none_or(|b| k.len() > b.len()) {
                    best = Some(k);
                }
            }
            match best {
                Some(k) => Key::O(name, k),
                None => Key::Plain,
            }
        }
    }
}

/// Whether line `code` begins another program of the file (Fanuc's `O`
/// line), which the reading passes over after the program's end.
pub fn is_program_line(lang: Language, code: &str) -> bool {
    matches!(key(lang, code), Key::Program(_))
}

/// Whether Sinumerik's `rest` holds a jump (`GOTOF`, `GOTOB`, `GOTO`,
/// `GOTOC`) as a word of its own.
pub fn has_goto(rest: &str) -> bool {
    rest.split_whitespace().any(|w| {
        matches!(
            w.to_ascii_uppercase().as_str(),
            "GOTO" | "GOTOF" | "GOTOB" | "GOTOC"
        )
    })
}

/// A file's landmarks.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Index {
    /// Lines of the file.
    pub lines: usize,
    /// Each block number's lines.
    numbers: BTreeMap<u32, Vec<usize>>,
    /// Each label's lines (Sinumerik).
    labels: BTreeMap<String, Vec<usize>>,
    /// Each program's `O` line (Fanuc).
    pub programs: BTreeMap<u32, usize>,
    /// Each opening statement's closing one (a loop's end, an `IF`'s
    /// `ELSE` or `ENDIF`, a `sub`'s `endsub`).
    close: BTreeMap<usize, usize>,
    /// Each closing statement's opening one.
    open: BTreeMap<usize, usize>,
    /// An `IF`'s or `ELSEIF`'s next branch (`ELSEIF`, `ELSE`, `ENDIF`).
    next_branch: BTreeMap<usize, usize>,
    /// The innermost loop around a line that breaks or continues it.
    loop_of: BTreeMap<usize, usize>,
    /// rs274ngc's subroutines by name: the `sub` line and its `endsub`.
    pub subs: BTreeMap<String, (usize, usize)>,
    /// The code of each structured line, for its condition read again.
    pub texts: BTreeMap<usize, String>,
}

/// An open structure while scanning.
struct Open {
    line: usize,
    what: Key,
    /// The last branch of an `IF` chain seen.
    branch: usize,
}

impl Index {
    /// The landmarks of the file whose lines' codes (comments blanked)
    /// `codes` gives, in `lang`.
    ///
    /// # Failures
    /// A structure not closed, closed by another's end, or an end without
    /// its opening: the line and why.
    pub fn build<'c>(
        lang: Language,
        codes: impl Iterator<Item = &'c str>,
    ) -> Result<Self, (usize, String)> {
        let mut ix = Index::default();
        let mut stack: Vec<Open> = Vec::new();
        for (i, code) in codes.enumerate() {
            ix.lines = i + 1;
            let p = parts(lang, code);
            if let Some(n) = p.number {
                ix.numbers.entry(n).or_default().push(i);
            }
            if let Some(l) = p.label {
                ix.labels.entry(l.to_ascii_uppercase()).or_default().push(i);
            }
            let k = key(lang, code);
            if let Key::Program(n) = k {
                if ix.programs.insert(n, i).is_some() {
                    return Err((i, format!("program O{n:04} stands twice in the file")));
                }
            }
            if k != Key::Plain {
                ix.texts.insert(i, code.to_owned());
            }
            ix.place(&mut stack, i, k)?;
        }
        if let Some(o) = stack.last() {
            return Err((o.line, format!("{} is never closed", shown(&o.what))));
        }
        Ok(ix)
    }

    /// Line `i`, which is `k`, into the structure open on `stack`.
    fn place(&mut self, stack: &mut Vec<Open>, i: usize, k: Key) -> Result<(), (usize, String)> {
        let opens = |k: &Key| match k {
            Key::While(_) | Key::Do(_) => true,
            Key::Sinumerik(s) => matches!(*s, "IF" | "WHILE" | "LOOP" | "FOR" | "REPEAT"),
            Key::O(_, s) => matches!(*s, "SUB" | "IF" | "WHILE" | "DO" | "REPEAT"),
            _ => false,
        };
        // An o-word `while` closes its `do` where one is open by its name.
        let closes_do = matches!(&k, Key::O(n, "WHILE") if stack.last().is_some_and(|o| matches!(&o.what, Key::O(m, "DO") if m == n)));
        if opens(&k) && !closes_do {
            if let Key::O(n, "SUB") = &k {
                if !stack.is_empty() {
                    return Err((i, format!("o{n} sub inside another structure")));
                }
            }
            stack.push(Open {
                line: i,
                what: k,
                branch: i,
            });
            return Ok(());
        }
        let partner = |o: &Key| -> Option<&'static str> {
            Some(match o {
                Key::While(_) | Key::Do(_) => "END",
                Key::Sinumerik("IF") => "ENDIF",
                Key::Sinumerik("WHILE") => "ENDWHILE",
                Key::Sinumerik("LOOP") => "ENDLOOP",
                Key::Sinumerik("FOR") => "ENDFOR",
                Key::Sinumerik("REPEAT") => "UNTIL",
                Key::O(_, "SUB") => "ENDSUB",
                Key::O(_, "IF") => "ENDIF",
                Key::O(_, "WHILE") => "ENDWHILE",
                Key::O(_, "DO") => "WHILE",
                Key::O(_, "REPEAT") => "ENDREPEAT",
                _ => return None,
            })
        };
        let word: &str = match &k {
            Key::End(_) => "END",
            Key::Sinumerik(s) if matches!(*s, "ELSE") => {
                let top = stack.last().filter(|o| o.what == Key::Sinumerik("IF"));
                let Some(top) = top else {
                    return Err((i, "ELSE without its IF".into()));
                };
                self.next_branch.insert(top.branch, i);
                if let Some(o) = stack.last_mut() {
                    o.branch = i;
                }
                return Ok(());
            }
            Key::Sinumerik(s) => s,
            Key::O(n, s) if matches!(*s, "ELSEIF" | "ELSE") => {
                let top = stack
                    .last()
                    .filter(|o| matches!(&o.what, Key::O(m, "IF") if m == n));
                let Some(top) = top else {
                    return Err((i, format!("o{n} {} without its o{n} if", s.to_lowercase())));
                };
                self.next_branch.insert(top.branch, i);
                if let Some(o) = stack.last_mut() {
                    o.branch = i;
                }
                return Ok(());
            }
            Key::O(n, s) if matches!(*s, "BREAK" | "CONTINUE" | "RETURN") => {
                let want = |o: &Open| match &o.what {
                    Key::O(m, w) if m == n => match *s {
                        "RETURN" => *w == "SUB",
                        _ => matches!(*w, "WHILE" | "DO" | "REPEAT"),
                    },
                    _ => false,
                };
                match stack.iter().rev().find(|o| want(o)) {
                    Some(o) => {
                        self.loop_of.insert(i, o.line);
                        return Ok(());
                    }
                    None => {
                        return Err((
                            i,
                            format!("o{n} {} outside its o{n} loop or sub", s.to_lowercase()),
                        ))
                    }
                }
            }
            Key::O(_, "CALL") => return Ok(()),
            Key::O(_, s) => s,
            _ => return Ok(()),
        };
        let Some(top) = stack.pop() else {
            return Err((i, format!("{word} without its opening statement")));
        };
        if partner(&top.what) != Some(word) || !same_name(&top.what, &k) {
            return Err((
                i,
                format!(
                    "{word} closes {}, opened on line {}",
                    shown(&top.what),
                    top.line + 1
                ),
            ));
        }
        if matches!(top.what, Key::Sinumerik("IF") | Key::O(_, "IF")) {
            self.next_branch.insert(top.branch, i);
        }
        if let Key::O(n, "SUB") = &top.what {
            let name = n.clone();
            if self.subs.insert(name.clone(), (top.line, i)).is_some() {
                return Err((top.line, format!("o{name} sub is defined twice")));
            }
        }
        self.close.insert(top.line, i);
        self.open.insert(i, top.line);
        Ok(())
    }

    /// The closing line of the structure opened on line `i`.
    pub fn close_of(&self, i: usize) -> Option<usize> {
        self.close.get(&i).copied()
    }

    /// The opening line of the structure closed on line `i`.
    pub fn open_of(&self, i: usize) -> Option<usize> {
        self.open.get(&i).copied()
    }

    /// The next branch (`ELSEIF`, `ELSE`, `ENDIF`) after the `IF` or
    /// `ELSEIF` on line `i`.
    pub fn next_branch(&self, i: usize) -> Option<usize> {
        self.next_branch.get(&i).copied()
    }

    /// The loop (or sub) a `break`, `continue` or `return` on line `i`
    /// belongs to.
    pub fn loop_of(&self, i: usize) -> Option<usize> {
        self.loop_of.get(&i).copied()
    }

    /// The line of block `N n` within lines `within`, searched from `from`
    /// on and then from the start (Fanuc's and Sinumerik's `GOTO`), or
    /// forward only or backward only.
    ///
    /// # Failures
    /// None there, or more than one (the control would take the first it
    /// meets: the verification refuses to guess which the programmer
    /// meant).
    pub(crate) fn number(
        &self,
        n: u32,
        within: std::ops::Range<usize>,
        from: usize,
        way: Way,
    ) -> Result<usize, String> {
        let lines = self.numbers.get(&n).map_or(&[][..], Vec::as_slice);
        found(&format!("N{n}"), lines, within, from, way)
    }

    /// The line of label `name` (Sinumerik), searched as [`Self::number`].
    ///
    /// # Failures
    /// As [`Self::number`].
    pub(crate) fn label(&self, name: &str, from: usize, way: Way) -> Result<usize, String> {
        let upper = name.to_ascii_uppercase();
        let lines = self.labels.get(&upper).map_or(&[][..], Vec::as_slice);
        found(
            &format!("the label {name}"),
            lines,
            0..self.lines,
            from,
            way,
        )
    }

    /// The lines of the program that line `i` is in (Fanuc: from its `O`
    /// line to the next program's; the whole file where it holds one).
    pub fn program_at(&self, i: usize) -> std::ops::Range<usize> {
        let start = self
            .programs
            .values()
            .copied()
            .filter(|l| *l <= i)
            .max()
            .unwrap_or(0);
        let end = self
            .programs
            .values()
            .copied()
            .filter(|l| *l > i)
            .min()
            .unwrap_or(self.lines);
        start..end
    }
}

/// Which way a jump searches.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Way {
    /// Forward from the jump, then from the start (Fanuc's `GOTO`,
    /// Sinumerik's `GOTO`).
    Around,
    /// Towards the end only (`GOTOF`).
    Forward,
    /// Towards the start only (`GOTOB`).
    Backward,
}

fn found(
    what: &str,
    lines: &[usize],
    within: std::ops::Range<usize>,
    from: usize,
    way: Way,
) -> Result<usize, String> {
    let inside: Vec<usize> = lines
        .iter()
        .copied()
        .filter(|l| within.contains(l))
        .collect();
    let hits: Vec<usize> = match way {
        Way::Around => inside.clone(),
        Way::Forward => inside.iter().copied().filter(|l| *l > from).collect(),
        Way::Backward => inside.iter().copied().filter(|l| *l < from).collect(),
    };
    match hits.as_slice() {
        [one] => Ok(*one),
        [] => Err(format!(
            "the jump's target {what} is not in the program{}",
            match way {
                Way::Forward => " after the jump",
                Way::Backward => " before the jump",
                Way::Around => "",
            }
        )),
        many => Err(format!(
            "the jump's target {what} stands on {} lines ({}): the verification does not guess which the control meets first",
            many.len(),
            many.iter()
                .take(4)
                .map(|l| format!("line {}", l + 1))
                .collect::<Vec<_>>()
                .join(", ")
        )),
    }
}

/// Whether closing statement `k` is of the structure `open` by its name:
/// Fanuc's `END m` of `DO m`, an o-word of its own number.
fn same_name(open: &Key, k: &Key) -> bool {
    match (open, k) {
        (Key::While(n) | Key::Do(n), Key::End(m)) => n == m,
        (Key::O(n, _), Key::O(m, _)) => n == m,
        _ => true,
    }
}

/// A structure's opening as a message names it.
fn shown(k: &Key) -> String {
    match k {
        Key::While(m) => format!("WHILE .. DO{m}"),
        Key::Do(m) => format!("DO{m}"),
        Key::End(m) => format!("END{m}"),
        Key::Program(n) => format!("O{n}"),
        Key::Sinumerik(s) => (*s).to_owned(),
        Key::O(n, s) => format!("o{n} {}", s.to_lowercase()),
        Key::Plain => "a block".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn structures_find_their_partners() {
        let fanuc = [
            "#1=0",
            "WHILE [#1 LT 3] DO1",
            "WHILE [#2 LT 3] DO2",
            "END2",
            "END1",
            "M30",
        ];
        let ix = Index::build(Language::Fanuc, fanuc.iter().copied()).unwrap();
        assert_eq!(ix.close_of(1), Some(4));
        assert_eq!(ix.close_of(2), Some(3));
        assert_eq!(ix.open_of(4), Some(1));
        let crossed = ["WHILE [1] DO1", "WHILE [1] DO2", "END1", "END2"];
        let e = Index::build(Language::Fanuc, crossed.iter().copied()).unwrap_err();
        assert_eq!(e.0, 2, "{e:?}");
        let sin = [
            "N10 IF R1>0",
            "G1 X1",
            "ELSE",
            "G1 X2",
            "ENDIF",
            "MARK1: G0 X0",
            "IF R1>0 GOTOB MARK1",
        ];
        let ix = Index::build(Language::Sinumerik, sin.iter().copied()).unwrap();
        assert_eq!(ix.next_branch(0), Some(2));
        assert_eq!(ix.next_branch(2), Some(4));
        assert_eq!(ix.label("mark1", 6, Way::Backward), Ok(5));
        assert!(ix.label("MARK1", 6, Way::Forward).is_err());
        let ngc = [
            "o100 sub",
            "o101 while [#1 lt 3]",
            "o101 break",
            "o101 endwhile",
            "o100 endsub",
            "o<edge> do",
            "o<edge> while [0]",
        ];
        let ix = Index::build(Language::Rs274, ngc.iter().copied()).unwrap();
        assert_eq!(ix.subs.get("100"), Some(&(0, 4)));
        assert_eq!(ix.close_of(1), Some(3));
        assert_eq!(ix.loop_of(2), Some(1));
        assert_eq!(ix.close_of(5), Some(6));
    }

    #[test]
    fn a_target_twice_is_refused() {
        let lines = ["N10 G0 X1", "N10 G0 X2", "GOTO 10"];
        let ix = Index::build(Language::Fanuc, lines.iter().copied()).unwrap();
        let e = ix.number(10, 0..3, 2, Way::Around).unwrap_err();
        assert!(e.contains("2 lines"), "{e}");
    }
}
