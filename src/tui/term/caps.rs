//! What the terminal can show, decided from the environment by simple rules
//! (issue 27, item 6): UTF-8 or ASCII only (the locale), colours or none
//! (`TERM`), and a size message that fits whatever the size.
use ratatui::buffer::Buffer;

/// Whether the locale's character set is UTF-8: the first of `LC_ALL`,
/// `LC_CTYPE`, `LANG` that is set and not empty decides. None set: UTF-8
/// is assumed (terminals are; minimal containers often set no locale), so
/// only a locale that says otherwise (`C`, `POSIX`, `en_US.ISO-8859-1`)
/// gets ASCII.
pub fn utf8_locale(env: &dyn Fn(&str) -> Option<String>) -> bool {
    ["LC_ALL", "LC_CTYPE", "LANG"]
        .iter()
        .find_map(|k| env(k).filter(|v| !v.is_empty()))
        .is_none_or(|v| {
            let v = v.to_ascii_lowercase();
            v.contains("utf-8") || v.contains("utf8")
        })
}

/// Whether a `TERM` names a terminal without colours: none given, `dumb`,
/// the `-mono` / `-m` entries of terminfo, and the DEC VTs (`vt100`,
/// `vt220`...) unless the name says colour.
pub fn monochrome(term: &str) -> bool {
    let t = term.to_ascii_lowercase();
    let dec_vt = t
        .strip_prefix("vt")
        .is_some_and(|r| r.starts_with(|c: char| c.is_ascii_digit()));
    t.is_empty()
        || t == "dumb"
        || t.ends_with("-mono")
        || t.ends_with("-m")
        || (dec_vt && !t.contains("color"))
}

/// The ASCII stand-in for a cell's symbol: box drawing to `+-|`, braille
/// by how many dots it has, blocks by how much they fill.
pub fn ascii(symbol: &str) -> &'static str {
    let mut chars = symbol.chars();
    let (Some(c), None) = (chars.next(), chars.next()) else {
        return if symbol.is_ascii() { "" } else { "?" };
    };
    match c {
        '\u{2800}' => " ",
        '\u{2801}'..='\u{28ff}' => match (c as u32 - 0x2800).count_ones() {
            1 => ".",
            2 => ":",
            3..=4 => "o",
            _ => "@",
        },
        '─' | '━' | '═' | '╌' | '┄' | '↔' | '−' | '–' | '—' => "-",
        '│' | '┃' | '║' | '╎' | '┆' => "|",
        '┌' | '┐' | '└' | '┘' | '├' | '┤' | '┬' | '┴' | '┼' | '╭' | '╮' | '╯' | '╰' | '╔' | '╗'
        | '╚' | '╝' => "+",
        '▀' | '▔' => "\"",
        '▁' | '▂' | '▄' => "_",
        '▃' | '▅' => "o",
        '▆' | '▇' | '█' | '▌' | '▐' => "#",
        '•' | '·' | '●' => "*",
        '→' => ">",
        '←' => "<",
        '↑' => "^",
        '↓' => "v",
        '×' => "x",
        '÷' => "/",
        '…' => ".",
        _ => "?",
    }
}

/// Every cell of `buf` in ASCII (a locale that is not UTF-8).
pub fn asciify(buf: &mut Buffer) {
    for cell in &mut buf.content {
        if !cell.symbol().is_ascii() {
            let s = ascii(cell.symbol());
            cell.set_symbol(s);
        }
    }
}

/// The message for a terminal smaller than `min`, as lines that fit in
/// `width` x `height`: the full sentence where there is room, shorter
/// forms below, down to one character at 1x1.
pub fn size_message(width: u16, height: u16, min: (u16, u16)) -> Vec<String> {
    let (mw, mh) = min;
    let candidates: [Vec<String>; 6] = [
        vec![
            format!("ballpit needs at least {mw}x{mh};"),
            format!("this terminal is {width}x{height}."),
            "q quits.".into(),
        ],
        vec![
            format!("needs {mw}x{mh},"),
            format!("this is {width}x{height}."),
            "q quits.".into(),
        ],
        vec![format!("needs {mw}x{mh},"), format!("is {width}x{height}")],
        vec![format!("need {mw}x{mh}")],
        vec![format!("{mw}x{mh}")],
        vec!["!".into()],
    ];
    let fits = |lines: &Vec<String>| {
        lines.len() <= usize::from(height)
            && lines
                .iter()
                .all(|l| l.chars().count() <= usize::from(width))
    };
    candidates
        .into_iter()
        .find(fits)
        .unwrap_or_else(|| vec![String::new()])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env_of<'a>(pairs: &'a [(&'a str, &'a str)]) -> impl Fn(&str) -> Option<String> + 'a {
        move |k| {
            pairs
                .iter()
                .find(|(n, _)| *n == k)
                .map(|(_, v)| (*v).to_string())
        }
    }

    #[test]
    fn the_first_locale_variable_set_decides() {
        assert!(utf8_locale(&env_of(&[])));
        assert!(utf8_locale(&env_of(&[("LANG", "en_US.UTF-8")])));
        assert!(utf8_locale(&env_of(&[("LANG", "C.utf8")])));
        assert!(!utf8_locale(&env_of(&[("LANG", "C")])));
        assert!(!utf8_locale(&env_of(&[
            ("LC_ALL", "POSIX"),
            ("LANG", "en_US.UTF-8")
        ])));
        assert!(!utf8_locale(&env_of(&[
            ("LC_ALL", ""),
            ("LC_CTYPE", "en_US.ISO-8859-1"),
            ("LANG", "en_US.UTF-8")
        ])));
        assert!(utf8_locale(&env_of(&[
            ("LC_CTYPE", "de_DE.UTF-8"),
            ("LANG", "C")
        ])));
    }

    #[test]
    fn terminals_without_colours() {
        for t in [
            "",
            "dumb",
            "xterm-mono",
            "vt100",
            "vt220",
            "VT102",
            "linux-m",
            "ansi-m",
        ] {
            assert!(monochrome(t), "{t}");
        }
        for t in [
            "xterm",
            "xterm-256color",
            "screen",
            "linux",
            "tmux-256color",
            "vte-256color",
            "vt100-color",
            "rxvt-unicode",
        ] {
            assert!(!monochrome(t), "{t}");
        }
    }

    #[test]
    fn ascii_stand_ins() {
        assert_eq!(ascii("│"), "|");
        assert_eq!(ascii("┌"), "+");
        assert_eq!(ascii("\u{2800}"), " ");
        assert_eq!(ascii("\u{2801}"), ".");
        assert_eq!(ascii("\u{28ff}"), "@");
        assert_eq!(ascii("▀"), "\"");
        assert_eq!(ascii("█"), "#");
        assert_eq!(ascii("ф"), "?");
        let mut buf = Buffer::with_lines(["┌─⠿ q→│", "ab÷×…"]);
        asciify(&mut buf);
        assert_eq!(buf, Buffer::with_lines(["+-@ q>|", "ab/x."]));
    }

    #[test]
    fn the_size_message_fits_at_every_size() {
        for w in 1..=80u16 {
            for h in 1..=24u16 {
                let m = size_message(w, h, (60, 20));
                assert!(!m.is_empty() && m.len() <= usize::from(h), "{w}x{h}");
                for l in &m {
                    assert!(
                        !l.is_empty() && l.chars().count() <= usize::from(w),
                        "{w}x{h}: {l}"
                    );
                }
            }
        }
        assert_eq!(
            size_message(40, 5, (60, 20)),
            [
                "ballpit needs at least 60x20;",
                "this terminal is 40x5.",
                "q quits."
            ]
        );
        assert_eq!(size_message(20, 5, (60, 20))[1], "this is 20x5.");
        assert_eq!(size_message(1, 1, (60, 20)), ["!"]);
    }
}
