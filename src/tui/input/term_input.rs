//! Bytes from the terminal to input events. The `input` thread is the only
//! reader of the terminal and feeds what it reads here; nothing else (in
//! particular not crossterm's event source, whose edge-triggered poll loses
//! keys that arrive together with a resize) ever reads stdin.
//!
//! Recognised: printable UTF-8, C0 controls (Ctrl-C …), a lone Esc (decided
//! by the caller's timeout, see [`Parser::flush_escape`]), CSI/SS3 arrows
//! with modifiers, the device status answer `ESC[0n` and cursor reports
//! `ESC[r;cR`, focus in/out, bracketed paste (its body is consumed and not
//! acted on: pasted text is not a sequence of commands). Everything else
//! (function keys, mouse reports, OSC/DCS strings) is consumed and dropped,
//! as are invalid bytes. Sequences may be split across reads anywhere.
use super::keys::Press;

/// What the terminal said.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Input {
    /// A key the key table can name (others are read and dropped).
    Key(Press),
    /// The answer to a device status request (`ESC[5n`): the terminal has
    /// consumed everything written before the request.
    StatusOk,
    /// A cursor position report (row, column, 1-based).
    Cursor(u16, u16),
    /// Focus gained (true) or lost.
    Focus(bool),
    /// A bracketed paste ended; its length in bytes (the body is dropped).
    Paste(usize),
}

const ESC: u8 = 0x1b;
const PASTE_END: &[u8] = b"\x1b[201~";
/// A sequence longer than this is garbage: drop it instead of growing.
const MAX_SEQUENCE: usize = 256;

/// An incremental parser; feed it whatever each read returned.
#[derive(Default)]
pub struct Parser {
    /// Bytes of an unfinished sequence or character.
    pending: Vec<u8>,
    /// Inside a bracketed paste: bytes seen so far.
    paste: Option<usize>,
}

impl Parser {
    pub fn new() -> Parser {
        Parser::default()
    }

    /// Whether only a lone Esc is waiting: the caller should call
    /// [`flush_escape`](Self::flush_escape) if nothing follows shortly.
    pub fn escape_pending(&self) -> bool {
        self.paste.is_none() && self.pending == [ESC]
    }

    /// Nothing followed a lone Esc in time: it was the Esc key.
    pub fn flush_escape(&mut self, out: &mut Vec<Input>) {
        if self.escape_pending() {
            self.pending.clear();
            out.push(Input::Key(Press::Esc));
        }
    }

    /// Parse `bytes`, appending complete events to `out`.
    pub fn feed(&mut self, bytes: &[u8], out: &mut Vec<Input>) {
        self.pending.extend_from_slice(bytes);
        let mut at = 0;
        while at < self.pending.len() {
            if let Some(len) = self.paste {
                if let Some(next) = self.paste_step(at, len) {
                    at = next;
                    out.push(Input::Paste(self.paste.take().unwrap_or(0)));
                    continue;
                }
                // Keep only what could be the start of the end marker.
                let keep = marker_prefix(&self.pending[at..]);
                let consumed = self.pending.len() - at - keep;
                self.paste = Some(len + consumed);
                at = self.pending.len() - keep;
                break;
            }
            match parse_one(&self.pending[at..]) {
                Step::Event(n, ev) => {
                    at += n;
                    match ev {
                        Some(Input::Paste(_)) => self.paste = Some(0),
                        Some(e) => out.push(e),
                        None => {}
                    }
                }
                Step::Incomplete => {
                    if self.pending.len() - at > MAX_SEQUENCE {
                        // Garbage that never ends: drop it all.
                        at = self.pending.len();
                    }
                    break;
                }
            }
        }
        self.pending.drain(..at);
    }

    /// In a paste: find the end marker from `at`; the index after it.
    fn paste_step(&mut self, at: usize, len: usize) -> Option<usize> {
        let rest = &self.pending[at..];
        let i = rest.windows(PASTE_END.len()).position(|w| w == PASTE_END)?;
        self.paste = Some(len + i);
        Some(at + i + PASTE_END.len())
    }
}

/// The length of the longest suffix of `b` that starts the paste end marker.
fn marker_prefix(b: &[u8]) -> usize {
    (1..PASTE_END.len())
        .rev()
        .find(|&k| k <= b.len() && b[b.len() - k..] == PASTE_END[..k])
        .unwrap_or(0)
}

enum Step {
    /// Bytes consumed and what they meant (None: ignored).
    Event(usize, Option<Input>),
    /// More bytes are needed.
    Incomplete,
}

fn key(p: Press) -> Input {
    Input::Key(p)
}

fn parse_one(b: &[u8]) -> Step {
    match b[0] {
        ESC => parse_escape(b),
        0x00 => Step::Event(1, Some(key(Press::Ctrl(' ')))),
        // Enter, Tab, Backspace and the other controls name no key of the
        // table (before the letters: Tab is Ctrl-I).
        b'\r' | b'\n' | b'\t' | 0x08 | 0x7f | 0x1c..=0x1f => Step::Event(1, None),
        c @ 0x01..=0x1a => Step::Event(1, Some(key(Press::Ctrl((c - 1 + b'a') as char)))),
        _ => parse_char(b),
    }
}

/// One UTF-8 character; invalid bytes are dropped one at a time.
fn parse_char(b: &[u8]) -> Step {
    let need = match b[0] {
        0x20..=0x7e => 1,
        0xc2..=0xdf => 2,
        0xe0..=0xef => 3,
        0xf0..=0xf4 => 4,
        _ => return Step::Event(1, None),
    };
    if b.len() < need {
        // A continuation byte that is not one makes it invalid already.
        if b[1..].iter().any(|&c| c & 0xc0 != 0x80) {
            return Step::Event(1, None);
        }
        return Step::Incomplete;
    }
    match std::str::from_utf8(&b[..need]) {
        Ok(s) => {
            // `P` is the key `P`: Shift is in the character.
            let c = s.chars().next().unwrap_or(' ');
            Step::Event(need, Some(key(Press::Char(c))))
        }
        Err(_) => Step::Event(1, None),
    }
}

fn parse_escape(b: &[u8]) -> Step {
    let Some(&second) = b.get(1) else {
        return Step::Incomplete;
    };
    match second {
        b'[' => parse_csi(b),
        b'O' => match b.get(2) {
            None => Step::Incomplete,
            Some(&f) => Step::Event(3, arrow(f).map(key)),
        },
        // OSC, DCS, APC, PM, SOS: strings ended by BEL or ESC \.
        b']' | b'P' | b'_' | b'^' | b'X' => parse_string(b),
        // Esc then a control (Esc, Ctrl-C …): the first was the Esc key.
        0x00..=0x1f | 0x7f => Step::Event(1, Some(key(Press::Esc))),
        // Alt + a character reads as the character.
        _ => match parse_char(&b[1..]) {
            Step::Event(n, ev) => Step::Event(1 + n, ev),
            Step::Incomplete => Step::Incomplete,
        },
    }
}

/// The arrow a final byte names; Home (`H`) and End (`F`) are read and
/// dropped.
fn arrow(f: u8) -> Option<Press> {
    Some(match f {
        b'A' => Press::Up,
        b'B' => Press::Down,
        b'C' => Press::Right,
        b'D' => Press::Left,
        _ => return None,
    })
}

/// `ESC [ params intermediates final`.
fn parse_csi(b: &[u8]) -> Step {
    let mut i = 2;
    // X10 mouse: `ESC [ M` and three raw bytes.
    if b.get(2) == Some(&b'M') {
        return if b.len() < 6 {
            Step::Incomplete
        } else {
            Step::Event(6, None)
        };
    }
    while i < b.len() && (0x20..=0x3f).contains(&b[i]) {
        i += 1;
    }
    let Some(&fin) = b.get(i) else {
        return Step::Incomplete;
    };
    let n = i + 1;
    if !(0x40..=0x7e).contains(&fin) {
        // Not a CSI after all: drop the introducer and go on from there.
        return Step::Event(2, None);
    }
    let params = std::str::from_utf8(&b[2..i]).unwrap_or("");
    let nums: Vec<u16> = params.split(';').map(|p| p.parse().unwrap_or(0)).collect();
    let first = nums.first().copied().unwrap_or(0);
    let ev = match fin {
        b'A' | b'B' | b'C' | b'D' | b'H' | b'F' if !params.starts_with(['<', '?', '>']) => {
            // Control + arrow is no key of the table; Shift and Alt are.
            let ctrl = nums.get(1).is_some_and(|&m| control_held(m));
            arrow(fin).filter(|_| !ctrl).map(key)
        }
        b'n' if params == "0" => Some(Input::StatusOk),
        b'R' if nums.len() == 2 && !params.starts_with('?') => {
            Some(Input::Cursor(nums[0], nums[1]))
        }
        b'I' if params.is_empty() => Some(Input::Focus(true)),
        b'O' if params.is_empty() => Some(Input::Focus(false)),
        b'~' if first == 200 => Some(Input::Paste(0)),
        _ => None,
    };
    Step::Event(n, ev)
}

/// Whether xterm's modifier parameter, 1 + (shift 1, alt 2, ctrl 4), has
/// Control.
fn control_held(m: u16) -> bool {
    m.saturating_sub(1) & 4 != 0
}

/// A string sequence, ended by BEL or ST (`ESC \`).
fn parse_string(b: &[u8]) -> Step {
    let mut i = 2;
    while i < b.len() {
        match b[i] {
            0x07 => return Step::Event(i + 1, None),
            ESC => {
                return match b.get(i + 1) {
                    None => Step::Incomplete,
                    Some(b'\\') => Step::Event(i + 2, None),
                    // A new sequence starts: the string was cut short.
                    Some(_) => Step::Event(i, None),
                };
            }
            _ => i += 1,
        }
    }
    Step::Incomplete
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(chunks: &[&[u8]]) -> Vec<Input> {
        let mut p = Parser::new();
        let mut out = Vec::new();
        for c in chunks {
            p.feed(c, &mut out);
        }
        p.flush_escape(&mut out);
        out
    }

    fn k(c: char) -> Input {
        key(Press::Char(c))
    }

    #[test]
    fn printable_utf8_and_controls() {
        assert_eq!(
            parse(&[b"vP] \x03\r\x7f"]),
            vec![k('v'), k('P'), k(']'), k(' '), key(Press::Ctrl('c')),]
        );
        assert_eq!(parse(&["é→".as_bytes()]), vec![k('é'), k('→')]);
    }

    #[test]
    fn lone_escape_waits_for_the_timeout_and_double_escape_is_two() {
        let mut p = Parser::new();
        let mut out = Vec::new();
        p.feed(b"\x1b", &mut out);
        assert!(out.is_empty());
        assert!(p.escape_pending());
        p.flush_escape(&mut out);
        assert_eq!(out, vec![key(Press::Esc)]);
        assert!(!p.escape_pending());
        assert_eq!(
            parse(&[b"\x1b\x1b"]),
            vec![key(Press::Esc), key(Press::Esc)]
        );
        assert_eq!(parse(&[b"\x1bv"]), vec![k('v')]);
        assert_eq!(
            parse(&[b"\x1b\x03"]),
            vec![key(Press::Esc), key(Press::Ctrl('c'))]
        );
    }

    #[test]
    fn arrows_csi_ss3_and_modifiers() {
        assert_eq!(
            parse(&[b"\x1b[A\x1bOB\x1b[1;5C\x1b[1;2D\x1b[H"]),
            vec![key(Press::Up), key(Press::Down), key(Press::Left),]
        );
    }

    #[test]
    fn other_sequences_are_consumed_and_ignored() {
        // F5, Delete, F1 (SS3), SGR mouse, X10 mouse, OSC colour answer, kitty key.
        let noise: &[u8] =
            b"\x1b[15~\x1b[3~\x1bOP\x1b[<0;10;5M\x1b[M !!\x1b]11;rgb:0/0/0\x07\x1b]0;t\x1b\\\x1b[97u";
        let mut bytes = noise.to_vec();
        bytes.push(b'v');
        assert_eq!(parse(&[&bytes]), vec![k('v')]);
    }

    #[test]
    fn status_cursor_and_focus_reports() {
        assert_eq!(
            parse(&[b"\x1b[0n\x1b[12;40R\x1b[I\x1b[Ov"]),
            vec![
                Input::StatusOk,
                Input::Cursor(12, 40),
                Input::Focus(true),
                Input::Focus(false),
                k('v')
            ]
        );
    }

    #[test]
    fn every_split_of_a_mixed_stream_gives_the_same_events() {
        let stream: &[u8] =
            b"a\x1b[1;5A\x1b[0n\x1b[200~qqq\x1b[A\x1b[201~\xc3\xa9\x1bOC\x1b[15~\x1b]0;x\x07]";
        let want = parse(&[stream]);
        assert_eq!(
            want,
            vec![
                k('a'),
                Input::StatusOk,
                Input::Paste(6),
                k('é'),
                key(Press::Right),
                k(']'),
            ]
        );
        for i in 0..=stream.len() {
            for j in i..=stream.len() {
                let got = parse(&[&stream[..i], &stream[i..j], &stream[j..]]);
                assert_eq!(got, want, "split at {i}, {j}");
            }
        }
        // One byte at a time.
        let bytes: Vec<&[u8]> = stream.chunks(1).collect();
        assert_eq!(parse(&bytes), want);
    }

    #[test]
    fn a_paste_body_is_not_keys_however_long_and_however_split() {
        let mut body = Vec::new();
        for i in 0..10_000u32 {
            body.push(b"qv]\x03\x1b"[(i % 5) as usize]);
        }
        let mut stream = b"\x1b[200~".to_vec();
        stream.extend_from_slice(&body);
        stream.extend_from_slice(b"\x1b[201~v");
        let want = vec![Input::Paste(body.len()), k('v')];
        assert_eq!(parse(&[&stream]), want);
        let chunks: Vec<&[u8]> = stream.chunks(7).collect();
        assert_eq!(parse(&chunks), want);
        // The end marker split right after its ESC.
        let cut = stream.len() - 7;
        assert_eq!(parse(&[&stream[..cut], &stream[cut..]]), want);
    }

    #[test]
    fn a_burst_of_keys_comes_out_in_order_exactly_once() {
        let keys: Vec<u8> = (0..1000).map(|i| b"v][m"[i % 4]).collect();
        let got = parse(&[&keys]);
        assert_eq!(got, keys.iter().map(|&c| k(c as char)).collect::<Vec<_>>());
    }

    #[test]
    fn invalid_utf8_is_dropped_without_losing_what_follows() {
        assert_eq!(
            parse(&[b"\xff\xc3v\x80\xe2\x82", b"\xacq\xf8"]),
            vec![k('v'), k('€'), k('q')]
        );
        // Garbage that looks like a never-ending sequence does not grow.
        let mut p = Parser::new();
        let mut out = Vec::new();
        let mut junk = b"\x1b[".to_vec();
        junk.extend(std::iter::repeat_n(b'1', 10_000));
        p.feed(&junk, &mut out);
        p.feed(b"v", &mut out);
        assert_eq!(out, vec![k('v')]);
        assert!(p.pending.is_empty());
    }
}
