//! A line as its control reads it: its comments checked and blanked in
//! place, the header's own lines where they stand, Sinumerik's own words
//! taken out; then its block: the number and the ISO words.

use super::{at_line, first_code, Block, OwnWord, Reader, Standing};
use crate::program::lint::LintError;
use crate::program::post::Dialect;

impl Reader<'_> {
    /// Line `i`'s code (`text` as its control reads it, [`read_line`]): a
    /// comment alone noted for the next move, the header's own lines
    /// blanked where they stand (the name and number the text gives
    /// itself noted; a subprogram file's name line and its `%` framing).
    pub(super) fn code_of(
        &self,
        at: &mut Standing,
        i: usize,
        text: &str,
    ) -> Result<String, LintError> {
        let (d, reading) = (self.d, self.reading);
        let (mut l, said) = read_line(d, i, text, reading).map_err(|m| self.fault(i, m))?;
        if l.trim().is_empty() {
            if let Some(s) = &said {
                at.pending = Some(s.clone());
            }
        }
        if self.current > 0 {
            // A subprogram's file: its name line and its framing.
            let named =
                (self.macros.and_then(|m| m.sub_name_line)).is_some_and(|(before, after)| {
                    i == 0 && text.starts_with(before) && text.ends_with(after)
                });
            if named || text == "%" {
                l = " ".repeat(text.len());
            }
            return Ok(l);
        }
        // A program read as it stands names itself.
        let own_name = (d.reading.name_line)
            .and_then(|(before, after)| text.strip_prefix(before)?.strip_suffix(after))
            .filter(|n| {
                reading && !n.is_empty() && n.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
            });
        let own_number = first_code(&l)
            .and_then(|w| w.strip_prefix('O'))
            .filter(|n| reading && n.len() == 4)
            .and_then(|n| n.parse::<u32>().ok());
        if i == 0 && (self.header_name.as_deref() == Some(text) || own_name.is_some()) {
            at.name = own_name.map(str::to_owned);
            l = " ".repeat(text.len());
        } else if self.framed && text == "%" && (i == 0 || i + 1 == self.lines) {
            l = " ".into();
        } else if d.reading.number_line
            && self.framed
            && i == 1
            && (first_code(&l).is_some_and(|w| w == self.program_number) || own_number.is_some())
        {
            at.number = own_number;
            // Fanuc's program number, `O0001`, is not an ISO word.
            let n = l.find('O').unwrap_or(0);
            l.replace_range(n..n + 5, "     ");
        }
        Ok(l)
    }

    /// Sinumerik's own words in line `i`'s code `l`, taken out of it
    /// (blanked in place).
    pub(super) fn own_words(&self, l: &mut String, i: usize) -> Result<Vec<OwnWord>, LintError> {
        let mut own = Vec::new();
        let code = l.clone();
        for word in code.split_whitespace() {
            let w = if let Some((_, diameter)) =
                (self.radial).filter(|(r, dm)| word == *r || word == *dm)
            {
                OwnWord::Radial(word == diameter)
            } else if let Some(list) = (self.d.feed_group)
                .and_then(|g| word.strip_prefix(g)?.strip_prefix('(')?.strip_suffix(')'))
            {
                OwnWord::FeedGroup(list.to_owned())
            } else if let Some(v) = self.start.and_then(|a| word.strip_prefix(a)) {
                OwnWord::StartAngle(
                    v.parse()
                        .map_err(|_| self.fault(i, format!("'{word}' is not a start angle")))?,
                )
            } else if let Some(v) = (self.d.reading.arcs)
                .and_then(|a| a.radius)
                .and_then(|a| word.strip_prefix(a))
            {
                let r = v.parse().map_err(|_| {
                    self.fault(i, format!("'{word}' is not an arc's radius (a number)"))
                })?;
                OwnWord::ArcRadius(r, word.to_owned())
            } else if let Some(v) = (self.d.reading.arcs)
                .and_then(|a| a.angle)
                .and_then(|a| word.strip_prefix(a))
            {
                let a = v.parse().map_err(|_| {
                    self.fault(
                        i,
                        format!("'{word}' is not an arc's opening angle (a number of degrees)"),
                    )
                })?;
                OwnWord::ArcAngle(a, word.to_owned())
            } else if let Some(v) = (self.d.reading.speed_clamp)
                .filter(|c| *c == crate::program::post::SpeedClamp::Lims)
                .and_then(|_| word.strip_prefix("LIMS="))
            {
                let s = v.parse().map_err(|_| {
                    self.fault(
                        i,
                        format!("'{word}' is not a spindle's clamp (a number of rpm)"),
                    )
                })?;
                OwnWord::SpeedLimit(s, word.to_owned())
            } else {
                continue;
            };
            own.push(w);
            *l = l.replacen(word, &" ".repeat(word.len()), 1);
        }
        Ok(own)
    }

    /// The block of line `i` (`text`; `code` its code, `own` Sinumerik's
    /// own words in it): its ISO words, its number checked against the
    /// dialect's numbering and the last; none where the line holds no
    /// block.
    pub(super) fn block_of(
        &self,
        at: &mut Standing,
        i: usize,
        text: &str,
        code: String,
        own: Vec<OwnWord>,
    ) -> Result<Option<Block>, LintError> {
        let has_code = !code.trim().is_empty() || !own.is_empty();
        let at_block = || {
            (code.split_whitespace().next())
                .filter(|w| {
                    w.len() > 1 && w.starts_with('N') && w[1..].bytes().all(|b| b.is_ascii_digit())
                })
                .map_or_else(|| at_line(i), str::to_owned)
        };
        let mut tokens =
            crate::program::words::words(&code).map_err(|m| self.err(at_block(), m.message))?;
        let number = match tokens.first() {
            Some(w) if w.letter == 'N' => {
                let n = w.integer().ok_or_else(|| {
                    self.fault(i, format!("{}: a block number is a whole number", w.text()))
                })?;
                tokens.remove(0);
                Some(n)
            }
            _ => None,
        };
        if let Some(w) = tokens.iter().find(|w| w.letter == 'N') {
            return Err(self.err(
                at_block(),
                format!("{}: a block number that does not open its block", w.text()),
            ));
        }
        if tokens.is_empty() && number.is_none() && own.is_empty() {
            if has_code {
                return Err(self.fault(
                    i,
                    format!(
                        "'{}' is not a block the {} can account for",
                        crate::files::excerpt(text),
                        if self.reading { "reader" } else { "lint" }
                    ),
                ));
            }
            return Ok(None);
        }
        let block = Block {
            line: i,
            number,
            code,
            tokens,
            own,
        };
        if at.st.ended {
            return Err(self.err(
                self.place(&block, at.k),
                format!(
                    "a block after the program's end ({})",
                    at.st.ended_by.as_deref().unwrap_or("")
                ),
            ));
        }
        self.numbered(at, &block)?;
        Ok(Some(block))
    }

    /// Block `b`'s number against the dialect's numbering and the last.
    fn numbered(&self, at: &mut Standing, b: &Block) -> Result<(), LintError> {
        // A program read as it stands numbers its blocks as its author
        // likes (the control needs no number, nor any order; a jump's
        // target is found by the statements' index, which refuses one
        // standing twice).
        if self.reading {
            return Ok(());
        }
        match (self.d.numbering, b.number) {
            (Some(_), None) => Err(self.fault(
                b.line,
                format!(
                    "a block without its number ('{}' opens it)",
                    b.code.split_whitespace().next().unwrap_or_default()
                ),
            )),
            (Some(_), Some(n)) => {
                if at.last_n.is_some_and(|m| n <= m) {
                    return Err(self.err(
                        format!("N{n}"),
                        format!("numbered out of order, after N{}", at.last_n.unwrap_or(0)),
                    ));
                }
                at.last_n = Some(n);
                Ok(())
            }
            (None, Some(n)) => {
                Err(self.fault(b.line, format!("N{n}: the dialect numbers no blocks")))
            }
            (None, None) => Ok(()),
        }
    }
}

/// Line `i` of a G-code program in `d` as its control reads it: the code
/// with its comments blanked in place (the same length, so the words'
/// spans index the line), after checking that every comment is one the
/// dialect's comment writer makes ([`crate::program::post::comment_text`]): closed
/// on its line, nothing but names' characters, nothing LinuxCNC acts on;
/// and that the line holds no character pilgrim never writes (a control
/// character such as a lone carriage return, which ends a line on some
/// controls; anything beyond ASCII). With it, the text of the line's last
/// comment.
pub(super) fn read_line(
    d: &Dialect,
    i: usize,
    line: &str,
    reading: bool,
) -> Result<(String, Option<String>), String> {
    // A shop's program may hold tabs, and anything in its comments; never
    // a control character that ends or changes a line on some controls.
    let bad = |c: char| {
        if reading {
            c.is_control() && c != '\t'
        } else {
            c.is_control() || !c.is_ascii()
        }
    };
    if let Some(c) = line.chars().find(|c| bad(*c)) {
        return Err(format!(
            "the character U+{:04X}, which {} (a carriage return or another control character ends or changes a line on some controls)",
            u32::from(c),
            if reading { "a control may read otherwise than the verification" } else { "pilgrim never writes" }
        ));
    }
    let check = |comment: &str| -> Result<(), String> {
        // A header line with nothing filled in is the dialect's own at its
        // place (Sinumerik's `;$PATH=/_N_MPF_DIR`), whatever it holds.
        if d.header
            .get(i)
            .is_some_and(|h| !h.contains('{') && *h == line)
        {
            return Ok(());
        }
        let text = comment.strip_prefix(' ').unwrap_or(comment);
        if reading {
            // A shop's program: its comments say what they like; only one
            // the control acts on is refused (a message is only shown).
            let shown = ["MSG", "DEBUG", "PRINT"].iter().any(|k| {
                (text.trim_start().get(..k.len())).is_some_and(|p| p.eq_ignore_ascii_case(k))
            });
            if crate::program::post::is_active_comment(d, text) && !shown {
                return Err(format!(
                    "the comment '({})' makes LinuxCNC act (a file, a probe, a script), which the verification does not follow",
                    crate::files::excerpt(comment)
                ));
            }
            return Ok(());
        }
        if let Some(c) = text.chars().find(|c| !crate::names::is_name_char(*c)) {
            return Err(format!(
                "'{c}' in the comment '{}', which pilgrim's comments never hold",
                crate::files::excerpt(comment)
            ));
        }
        if d.upper_comments && text.chars().any(|c| c.is_ascii_lowercase()) {
            return Err(format!(
                "lower case in the comment '{}', which the control may refuse",
                crate::files::excerpt(comment)
            ));
        }
        if crate::program::post::is_active_comment(d, text) {
            return Err(format!(
                "the comment '({})' makes LinuxCNC act (a message, a file, a script)",
                crate::files::excerpt(comment)
            ));
        }
        Ok(())
    };
    let mut code = String::with_capacity(line.len());
    let mut said = None;
    if d.comment.1.is_empty() {
        // A comment runs from its opening (`;`) to the line's end.
        let open = d.comment.0.trim_end();
        let (c, comment) = match line.find(open) {
            Some(p) => (&line[..p], Some(&line[p + open.len()..])),
            None => (line, None),
        };
        if let Some(comment) = comment {
            check(comment)?;
            said = Some(comment.strip_prefix(' ').unwrap_or(comment).to_owned());
        }
        code.push_str(c);
        code.push_str(&" ".repeat(line.len() - c.len()));
        if !line.is_ascii() {
            ascii_code(&code)?;
        }
        return Ok((code, said));
    }
    // Parenthesised comments, closed on their line, none inside another.
    let mut rest = line;
    while let Some(p) = rest.find(['(', ')', ';']) {
        code.push_str(&rest[..p]);
        match rest.as_bytes()[p] {
            b'(' => {
                let inner = &rest[p + 1..];
                let Some(q) = inner.find(')') else {
                    return Err("a comment '(' that its line does not close".into());
                };
                let comment = &inner[..q];
                if comment.contains('(') {
                    return Err("a comment inside a comment".into());
                }
                check(comment)?;
                said = Some(comment.strip_prefix(' ').unwrap_or(comment).to_owned());
                code.push_str(&" ".repeat(q + 2));
                rest = &inner[q + 1..];
            }
            b')' => return Err("')' outside a comment".into()),
            // rs274ngc reads `;` as a comment to the line's end.
            _ if reading
                && d.reading
                    .macros
                    .is_some_and(|m| m.language == crate::program::macros::Language::Rs274) =>
            {
                let comment = &rest[p + 1..];
                check(comment)?;
                said = Some(comment.trim().to_owned());
                code.push_str(&" ".repeat(rest.len() - p));
                return Ok((code, said));
            }
            _ => return Err("';', which pilgrim never writes in this dialect".into()),
        }
    }
    code.push_str(rest);
    if !line.is_ascii() {
        ascii_code(&code)?;
    }
    Ok((code, said))
}

/// A block's code (its comments blanked) holds ASCII only: a control reads
/// no other character as a word's.
fn ascii_code(code: &str) -> Result<(), String> {
    match code.chars().find(|c| !c.is_ascii()) {
        Some(c) => Err(format!(
            "the character U+{:04X} outside a comment, which no control reads in a block",
            u32::from(c)
        )),
        None => Ok(()),
    }
}
