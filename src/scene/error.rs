//! Scene errors that point at the file, line and column of the problem.

use std::fmt;

/// Characters shown on each side of the column when a line is too long to show whole.
pub const EXCERPT_RADIUS: usize = 60;

/// Longest message, in characters; a longer one (quoting a huge name, say) is cut in the
/// middle with `…`.
pub const MAX_MESSAGE: usize = 600;

/// A scene that could not be loaded, with where and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SceneError {
    /// The file the error is in, as the user named it.
    pub file: String,
    /// 1-based line and column (in characters), when the error has a place in the file.
    pub at: Option<(usize, usize)>,
    /// What is wrong.
    pub message: String,
    /// The offending line of the file, shown under the message with a caret: the whole line,
    /// or, when it is long, a window of [`EXCERPT_RADIUS`] characters each side of the column,
    /// with `…` where it is cut.
    pub line_text: Option<String>,
    /// 0-based character index in `line_text` that the caret points at.
    pub caret: usize,
}

/// `s` with at most `max` characters: a longer string keeps its start and end around `…`.
pub fn clip(s: &str, max: usize) -> String {
    let n = s.chars().count();
    if n <= max {
        return s.to_string();
    }
    let head = max * 2 / 3;
    let tail = max.saturating_sub(head + 1);
    let start: String = s.chars().take(head).collect();
    let end: String = s.chars().skip(n - tail).collect();
    format!("{start}…{end}")
}

/// A message cut to [`MAX_MESSAGE`] characters, as every error's is.
pub fn clip_message(message: &str) -> String {
    clip(message, MAX_MESSAGE)
}

/// The window of `line` shown for 1-based column `col`, and the caret's index in it.
fn excerpt(line: &str, col: usize) -> (String, usize) {
    let caret = col.saturating_sub(1);
    let n = line.chars().count();
    if n <= 2 * EXCERPT_RADIUS + 1 {
        return (line.to_string(), caret);
    }
    let from = caret.saturating_sub(EXCERPT_RADIUS);
    let to = (caret + EXCERPT_RADIUS + 1).min(n);
    let mut text: String = if from > 0 {
        "…".into()
    } else {
        String::new()
    };
    text.extend(line.chars().skip(from).take(to.saturating_sub(from)));
    if to < n {
        text.push('…');
    }
    (text, caret - from + usize::from(from > 0))
}

impl SceneError {
    /// An error with no position in the file (unreadable file).
    pub fn whole_file(file: &str, message: impl Into<String>) -> Self {
        SceneError {
            file: file.to_string(),
            at: None,
            message: clip(&message.into(), MAX_MESSAGE),
            line_text: None,
            caret: 0,
        }
    }

    /// An error at a 1-based `(line, col)` of `text` (`col` counts characters).
    pub fn at(file: &str, text: &str, line: usize, col: usize, message: impl Into<String>) -> Self {
        let (line_text, caret) = match text.split('\n').nth(line.saturating_sub(1)) {
            Some(l) => {
                let (t, c) = excerpt(l.strip_suffix('\r').unwrap_or(l), col);
                (Some(t), c)
            }
            None => (None, 0),
        };
        SceneError {
            file: file.to_string(),
            at: Some((line, col)),
            message: clip(&message.into(), MAX_MESSAGE),
            line_text,
            caret,
        }
    }

    /// An error at a byte offset of `text` (clamped to the text, and back to a character
    /// boundary).
    pub fn at_offset(file: &str, text: &str, offset: usize, message: impl Into<String>) -> Self {
        let (line, col) = line_col(text, offset);
        Self::at(file, text, line, col, message)
    }
}

/// 1-based line and column (in characters) of byte `offset` of `text`.
pub fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let mut offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.at {
            Some((line, col)) => {
                write!(f, "{}:{line}:{col}: {}", self.file, self.message)?;
                if let Some(text) = &self.line_text {
                    let gutter = line.to_string().len();
                    let pad: String = text
                        .chars()
                        .take(self.caret)
                        .map(|c| if c == '\t' { '\t' } else { ' ' })
                        .collect();
                    write!(
                        f,
                        "\n{:gutter$} |\n{line} | {text}\n{:gutter$} | {pad}^",
                        "", ""
                    )?;
                }
                Ok(())
            }
            None => write!(f, "{}: {}", self.file, self.message),
        }
    }
}

impl std::error::Error for SceneError {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_line_shows_a_window_with_the_caret_under_the_column() {
        let mut line = "a".repeat(4 << 20);
        let col = 2_000_001;
        line.replace_range(col - 1..col, "X");
        let e = SceneError::at("big.ron", &line, 1, col, "bad");
        let shown = e.to_string();
        assert!(shown.len() < 400, "{} bytes", shown.len());
        let lines: Vec<&str> = shown.lines().collect();
        let text = lines[2].strip_prefix("1 | ").unwrap();
        let caret = lines[3].strip_prefix("  | ").unwrap();
        assert!(text.starts_with('…') && text.ends_with('…'), "{text}");
        assert_eq!(caret.chars().count() - 1, e.caret);
        assert_eq!(text.chars().nth(e.caret), Some('X'));
        // Near either end the window is cut on one side only.
        let e = SceneError::at("big.ron", &line, 1, 3, "bad");
        assert!(!e.line_text.as_ref().unwrap().starts_with('…') && e.caret == 2);
        let e = SceneError::at("big.ron", &line, 1, line.len(), "bad");
        let t = e.line_text.unwrap();
        assert!(t.starts_with('…') && !t.ends_with('…'));
        assert_eq!(t.chars().count() - 1, e.caret);
    }

    #[test]
    fn long_messages_are_clipped() {
        let e = SceneError::whole_file("f", "x".repeat(10_000));
        assert_eq!(e.message.chars().count(), MAX_MESSAGE);
        assert_eq!(clip("short", 10), "short");
    }

    #[test]
    fn offsets_inside_a_character_and_past_the_end_are_safe() {
        let text = "ab\ncé\n";
        assert_eq!(line_col(text, 5), (2, 2));
        assert_eq!(line_col(text, 100), (3, 1));
        assert_eq!(line_col(text, 0), (1, 1));
    }
}
