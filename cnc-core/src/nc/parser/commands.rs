//! The `#` commands (`#TRACK CS`, `#CS`, `#MSG`...), one method each, and the bracketed
//! lists of entries they take.

use super::Parser;
use crate::nc::ast::*;
use crate::nc::lexer::Tok;

const TRACK_FLAGS: &[&str] = &[
    "SET_ZERO",
    "ABSOLUTE",
    "KIN_BASE",
    "WAIT",
    "ROT_TRANS",
    "RELATIVE",
    "SIMU",
];
const TRACK_VALUES: &[&str] = &[
    "CH", "ID", "OPTION", "FILTER", "X", "Y", "Z", "A", "B", "C", "LOG_FILE",
];

impl Parser<'_> {
    fn on_off(&mut self, context: &str) -> Option<bool> {
        match self.peek() {
            Tok::Word(w) if w == "ON" => {
                self.bump();
                Some(true)
            }
            Tok::Word(w) if w == "OFF" => {
                self.bump();
                Some(false)
            }
            _ => {
                let (span, found) = (self.span(), self.describe());
                self.error(
                    span,
                    format!("{context}: expected ON or OFF, found {found}"),
                );
                None
            }
        }
    }

    /// A `#` command, the cursor after the `#` (`span` runs to the end of the block). A command
    /// that cannot be read is reported and gives `None`. Then the rest of the block is skipped,
    /// except where a part of the command failed (its ON/OFF, its bracket list, an axis name,
    /// or `#TRAFO` given neither ON, OFF nor an id): parsing goes on where that part stopped.
    pub(super) fn command(&mut self, span: Span) -> Option<Command> {
        let name = match self.peek().clone() {
            Tok::Word(w) if !self.token().spaced => {
                self.bump();
                w
            }
            _ => {
                let found = self.describe();
                self.error(
                    span,
                    format!("expected a command name after \"#\", found {found}"),
                );
                self.recover();
                return None;
            }
        };
        match name.as_str() {
            "TRACK" | "TRACK_CS" => self.track_cs(name),
            "CHANNEL" => self.channel_interface(),
            "CS" => self.cs(span),
            "TRAFO" => self.trafo(span),
            "KIN" => self.kin_id(span),
            "SIGNAL" => self.signal_syn(),
            "WAIT" => self.wait(span),
            "FLUSH" => self.flush(span),
            "PSET" => self.pset(span),
            "PRESET" => self.preset(),
            "MSG" => self.msg(span),
            "TIME" => self.time(),
            "CONTOUR" => self.contour(),
            "VAR" => Some(Command::Var),
            "ENDVAR" => Some(Command::EndVar),
            "COMMENT" => {
                self.error(
                    span,
                    "#COMMENT END without #COMMENT BEGIN (a comment section is #COMMENT BEGIN ... #COMMENT END, each on its own line)",
                );
                self.recover();
                None
            }
            other => {
                self.error(
                    span,
                    format!("unknown command \"#{other}\" (known: #TRACK CS, #CHANNEL INTERFACE, #CS, #TRAFO, #KIN ID, #SIGNAL SYN, #WAIT SYN, #WAIT INDP, #FLUSH, #PSET, #PRESET, #MSG, #TIME, #CONTOUR MODE, #VAR, #ENDVAR, #COMMENT BEGIN/END)"),
                );
                self.recover();
                None
            }
        }
    }

    /// `#TRACK CS ABS`, `#TRACK CS ON|OFF [options]` (`name` is `TRACK` or `TRACK_CS`).
    fn track_cs(&mut self, name: Name) -> Option<Command> {
        if name == "TRACK" && !self.expect_word("CS", "#TRACK CS") {
            self.recover();
            return None;
        }
        if self.is_word("ABS") {
            self.bump();
            return Some(Command::TrackCsAbs);
        }
        let on = self.on_off("#TRACK CS")?;
        let options = if self.is_punct("[") {
            self.bracket_list()?
        } else {
            Vec::new()
        };
        self.check_track_options(&options);
        Some(Command::TrackCs { on, options })
    }

    /// `#CHANNEL INTERFACE ON|OFF [DYN_CS|TRACK_CS]`, after `CHANNEL`.
    fn channel_interface(&mut self) -> Option<Command> {
        if !self.expect_word("INTERFACE", "#CHANNEL INTERFACE") {
            self.recover();
            return None;
        }
        let on = self.on_off("#CHANNEL INTERFACE")?;
        let mut kind = None;
        if self.is_punct("[") {
            let entries = self.bracket_list()?;
            for e in entries {
                match (&e.key, &e.value, e.glued) {
                    (Some(k), None, None) if k == "DYN_CS" || k == "TRACK_CS" => {
                        if kind.replace(*k).is_some() {
                            self.error(e.span, "#CHANNEL INTERFACE names its interface once");
                        }
                    }
                    _ => self.error(e.span, "#CHANNEL INTERFACE: expected DYN_CS or TRACK_CS"),
                }
            }
        }
        Some(Command::ChannelInterface { on, kind })
    }

    /// `#CS ON|OFF [name] [values]`, after `CS`.
    fn cs(&mut self, span: Span) -> Option<Command> {
        let on = self.on_off("#CS")?;
        let mut name = None;
        let mut values = Vec::new();
        let mut lists = 0;
        while self.is_punct("[") {
            lists += 1;
            let entries = self.bracket_list()?;
            let is_name = entries.len() == 1
                && entries[0].key.is_some()
                && entries[0].value.is_none()
                && entries[0].glued.is_none();
            if is_name && name.is_none() && values.is_empty() {
                name = entries[0].key;
            } else {
                for e in entries {
                    match (e.key, e.value) {
                        (None, Some(v)) => values.push(v),
                        _ => self.error(
                            e.span,
                            "#CS: expected a value (number, variable or expression)",
                        ),
                    }
                }
            }
            if lists > 2 {
                self.error(span, "#CS takes at most a name list and a value list");
            }
        }
        Some(Command::Cs { on, name, values })
    }

    /// `#TRAFO ON|OFF`, `#TRAFO [id]`, `#TRAFO ON [id]`, after `TRAFO`.
    fn trafo(&mut self, span: Span) -> Option<Command> {
        let on = match self.peek() {
            Tok::Word(w) if w == "ON" || w == "OFF" => self.on_off("#TRAFO"),
            _ => None,
        };
        let id = if self.is_punct("[") {
            let entries = self.bracket_list()?;
            match entries.as_slice() {
                [Entry {
                    key: None,
                    value: Some(v),
                    ..
                }] => Some(v.clone()),
                _ => {
                    self.error(span, "#TRAFO [..]: expected one kinematic id");
                    None
                }
            }
        } else {
            None
        };
        if on.is_none() && id.is_none() {
            let found = self.describe();
            self.error(
                span,
                format!("#TRAFO: expected ON, OFF or [id], found {found}"),
            );
            return None;
        }
        Some(Command::Trafo { on, id })
    }

    /// `#KIN ID [id]`, after `KIN`.
    fn kin_id(&mut self, span: Span) -> Option<Command> {
        if !self.expect_word("ID", "#KIN ID") {
            self.recover();
            return None;
        }
        let entries = if self.is_punct("[") {
            self.bracket_list()?
        } else {
            Vec::new()
        };
        match entries.as_slice() {
            [Entry {
                key: None,
                value: Some(v),
                ..
            }] => Some(Command::KinId { id: v.clone() }),
            _ => {
                self.error(span, "#KIN ID: expected [id]");
                self.recover();
                None
            }
        }
    }

    /// `#SIGNAL SYN [ID.. COUNT..]`, after `SIGNAL`.
    fn signal_syn(&mut self) -> Option<Command> {
        if !self.expect_word("SYN", "#SIGNAL SYN") {
            self.recover();
            return None;
        }
        let options = self.required_list("#SIGNAL SYN")?;
        self.check_keys(&options, &["ID", "COUNT"], "#SIGNAL SYN");
        Some(Command::SignalSyn { options })
    }

    /// `#WAIT SYN [ID..]`, `#WAIT INDP ALL`, after `WAIT`.
    fn wait(&mut self, span: Span) -> Option<Command> {
        match self.peek().clone() {
            Tok::Word(w) if w == "SYN" => {
                self.bump();
                let options = self.required_list("#WAIT SYN")?;
                self.check_keys(&options, &["ID"], "#WAIT SYN");
                Some(Command::WaitSyn { options })
            }
            Tok::Word(w) if w == "INDP" => {
                self.bump();
                if self.expect_word("ALL", "#WAIT INDP ALL") {
                    Some(Command::WaitIndpAll)
                } else {
                    self.recover();
                    None
                }
            }
            _ => {
                let found = self.describe();
                self.error(span, format!("#WAIT: expected SYN or INDP, found {found}"));
                self.recover();
                None
            }
        }
    }

    /// `#FLUSH WAIT|CONTINUE`, after `FLUSH`.
    fn flush(&mut self, span: Span) -> Option<Command> {
        match self.peek().clone() {
            Tok::Word(w) if w == "WAIT" || w == "CONTINUE" => {
                self.bump();
                Some(Command::Flush { wait: w == "WAIT" })
            }
            _ => {
                let found = self.describe();
                self.error(
                    span,
                    format!("#FLUSH: expected WAIT or CONTINUE, found {found}"),
                );
                self.recover();
                None
            }
        }
    }

    /// `#PSET X=10 ...`, after `PSET`.
    fn pset(&mut self, span: Span) -> Option<Command> {
        let mut axes = Vec::new();
        while matches!(self.peek(), Tok::Word(_) | Tok::Addr(..)) {
            let s = self.span();
            match self.word_item(s) {
                Some(Item::Axis(a)) => axes.push(a),
                _ => self.error(s, "#PSET: expected axis assignments such as X=10"),
            }
        }
        if axes.is_empty() {
            self.error(span, "#PSET: expected at least one axis assignment");
        }
        Some(Command::Pset { axes })
    }

    /// `#PRESET`, `#PRESET X ...`, after `PRESET`.
    fn preset(&mut self) -> Option<Command> {
        let mut axes = Vec::new();
        while let Some((w, glued)) = self.take_word() {
            let s = self.span();
            axes.push(self.axis_name(w, glued, s)?);
        }
        Some(Command::Preset { axes })
    }

    /// `#MSG ["text"]`, also `#MSG SAVE ["text"]` (the message is shown either way), after
    /// `MSG`.
    fn msg(&mut self, span: Span) -> Option<Command> {
        if self.is_word("SAVE") {
            self.bump();
        }
        let text = if self.is_punct("[") {
            self.bump();
            let text = match self.peek().clone() {
                Tok::Str(t) => {
                    self.bump();
                    Some(t)
                }
                _ => None,
            };
            if self.is_punct("]") {
                self.bump();
            } else {
                self.error(span, "#MSG: expected \"]\" after the text");
            }
            text
        } else {
            None
        };
        match text {
            Some(t) => Some(Command::Msg {
                text: std::sync::Arc::from(t),
            }),
            None => {
                self.error(span, "#MSG: expected [\"text\"]");
                self.recover();
                None
            }
        }
    }

    /// `#TIME t`, after `TIME`.
    fn time(&mut self) -> Option<Command> {
        let Some(seconds) = self.expr() else {
            self.recover();
            return None;
        };
        Some(Command::Time { seconds })
    }

    /// `#CONTOUR MODE [DEV PATH_DEV=..]`, after `CONTOUR`.
    fn contour(&mut self) -> Option<Command> {
        if !self.expect_word("MODE", "#CONTOUR MODE") {
            self.recover();
            return None;
        }
        let options = self.required_list("#CONTOUR MODE")?;
        for e in &options {
            let ok = matches!(
                (e.key.as_deref(), e.glued.is_some() || e.value.is_some()),
                (Some("DEV"), false) | (Some("PATH_DEV"), true)
            );
            if !ok {
                self.error(
                    e.span,
                    "#CONTOUR MODE: expected DEV and PATH_DEV=<mm> (corner deviation; the other contouring modes are not supported)",
                );
            }
        }
        Some(Command::Contour { options })
    }

    fn required_list(&mut self, context: &str) -> Option<Vec<Entry>> {
        if self.is_punct("[") {
            self.bracket_list()
        } else {
            let (span, found) = (self.span(), self.describe());
            self.error(span, format!("{context}: expected \"[\", found {found}"));
            None
        }
    }

    fn check_keys(&mut self, entries: &[Entry], allowed: &[&str], context: &str) {
        for e in entries {
            let ok = e.key.as_deref().is_some_and(|k| allowed.contains(&k))
                && (e.glued.is_some() || e.value.is_some());
            if !ok {
                self.error(
                    e.span,
                    format!("{context}: expected {} with a value", allowed.join(" or ")),
                );
            }
        }
    }

    fn check_track_options(&mut self, entries: &[Entry]) {
        for e in entries {
            let Some(key) = e.key.as_deref() else {
                self.error(e.span, "#TRACK CS: expected an option name");
                continue;
            };
            if TRACK_FLAGS.contains(&key) {
                if e.value.is_some() || e.glued.is_some() || e.text.is_some() {
                    self.error(e.span, format!("#TRACK CS: option {key} takes no value"));
                }
            } else if TRACK_VALUES.contains(&key) {
                if e.value.is_none() && e.text.is_none() && e.glued.is_none() {
                    self.error(
                        e.span,
                        format!("#TRACK CS: option {key} needs a value: {key}=..."),
                    );
                }
            } else {
                self.error(
                    e.span,
                    format!("#TRACK CS: unknown option \"{key}\" (expected CH, ID, SET_ZERO, ABSOLUTE, OPTION, KIN_BASE, FILTER, WAIT, ROT_TRANS, RELATIVE, X, Y, Z, A, B, C, SIMU or LOG_FILE)"),
                );
            }
        }
    }

    /// `[ entry entry, entry ... ]`; the list may run over several lines.
    pub(super) fn bracket_list(&mut self) -> Option<Vec<Entry>> {
        let open = self.span();
        self.bump(); // [
        let mut entries = Vec::new();
        loop {
            match self.peek().clone() {
                Tok::Punct("]") => {
                    self.bump();
                    return Some(entries);
                }
                Tok::Punct(",") => {
                    self.bump();
                }
                Tok::Newline => {
                    self.error(open, "\"[\" is not closed by \"]\"");
                    return None;
                }
                // A P parameter or a function is a value, not a key.
                Tok::Word(_) | Tok::Addr(..) if !self.starts_expression() => {
                    let span = self.span();
                    let (w, glued) = self.take_word()?;
                    let (mut value, mut text) = (None, None);
                    if self.is_punct("=") {
                        self.bump();
                        if let Tok::Str(s) = self.peek().clone() {
                            self.bump();
                            text = Some(std::sync::Arc::from(s));
                        } else {
                            value = Some(self.expr()?);
                        }
                    }
                    entries.push(Entry {
                        key: Some(w),
                        glued,
                        value,
                        text,
                        span: self.extend(span),
                    });
                }
                _ => {
                    let span = self.span();
                    let value = self.expr()?;
                    entries.push(Entry {
                        key: None,
                        glued: None,
                        value: Some(value),
                        text: None,
                        span: self.extend(span),
                    });
                }
            }
        }
    }
}
