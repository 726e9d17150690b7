//! Text in rows of a panel's width, broken between words: the readouts'
//! notices wrap with it, and the layout counts their rows with it.
use unicode_width::{UnicodeWidthChar, UnicodeWidthStr};

/// `text` in rows of at most `width` columns, broken between words, so no
/// word is split at the border; a word wider than a row (a path) is cut,
/// after a `/` where it can be.
pub fn wrap(text: &str, width: usize) -> Vec<String> {
    let width = width.max(1);
    let mut rows: Vec<String> = Vec::new();
    let mut row = String::new();
    for word in text.split_whitespace() {
        if !row.is_empty() && row.width() + 1 + word.width() <= width {
            row.push(' ');
            row.push_str(word);
            continue;
        }
        if !row.is_empty() {
            rows.push(std::mem::take(&mut row));
        }
        let mut rest = word;
        while rest.width() > width {
            let fit = prefix_fitting(rest, width);
            let cut = rest[..fit]
                .rfind('/')
                .filter(|&i| i > 0)
                .map_or(fit, |i| i + 1);
            rows.push(rest[..cut].to_string());
            rest = &rest[cut..];
        }
        row = rest.to_string();
    }
    if !row.is_empty() {
        rows.push(row);
    }
    rows
}

/// The bytes of the longest start of `word` at most `width` columns wide
/// (one character at least, so a cut always moves on).
fn prefix_fitting(word: &str, width: usize) -> usize {
    let mut used = 0;
    for (i, c) in word.char_indices() {
        used += c.width().unwrap_or(0);
        if used > width {
            return if i == 0 { c.len_utf8() } else { i };
        }
    }
    word.len()
}

#[cfg(test)]
mod tests {
    use super::wrap;

    #[test]
    fn wraps_between_words_and_cuts_only_words_wider_than_a_row() {
        assert_eq!(
            wrap("count limit: 1 sphere", 12),
            ["count limit:", "1 sphere"]
        );
        // Spaces in the text do not count: one between words.
        assert_eq!(wrap("  a   b  ", 3), ["a b"]);
        assert_eq!(wrap("exactly ten", 11), ["exactly ten"]);
        assert_eq!(wrap("exactly ten", 10), ["exactly", "ten"]);
        // A path wider than a row: cut after a slash, else where it must.
        assert_eq!(
            wrap("read /home/someone/scene.toml: gone", 16),
            ["read", "/home/someone/", "scene.toml: gone"]
        );
        assert_eq!(wrap("abcdefgh", 3), ["abc", "def", "gh"]);
        // A character wider than the row still moves on.
        assert_eq!(wrap("日本", 1), ["日", "本"]);
        assert!(wrap("", 5).is_empty());
    }
}
