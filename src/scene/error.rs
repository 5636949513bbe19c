//! Scene errors that point at the file, line and column of the problem.

use std::fmt;

/// A scene that could not be loaded, with where and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SceneError {
    /// The file the error is in, as the user named it.
    pub file: String,
    /// 1-based line and column, when the error has a place in the file.
    pub at: Option<(usize, usize)>,
    /// What is wrong.
    pub message: String,
    /// The offending line of the file, shown under the message with a caret.
    pub line_text: Option<String>,
}

impl SceneError {
    /// An error with no position in the file (unreadable file, include cycle).
    pub fn whole_file(file: &str, message: impl Into<String>) -> Self {
        SceneError {
            file: file.to_string(),
            at: None,
            message: message.into(),
            line_text: None,
        }
    }

    /// An error at a 1-based `(line, col)` of `text`.
    pub fn at(file: &str, text: &str, line: usize, col: usize, message: impl Into<String>) -> Self {
        SceneError {
            file: file.to_string(),
            at: Some((line, col)),
            message: message.into(),
            line_text: text.lines().nth(line.saturating_sub(1)).map(str::to_string),
        }
    }

    /// An error at a byte offset of `text`.
    pub fn at_offset(file: &str, text: &str, offset: usize, message: impl Into<String>) -> Self {
        let before = &text[..offset.min(text.len())];
        let line = before.matches('\n').count() + 1;
        let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        Self::at(file, text, line, col, message)
    }
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
                        .take(col.saturating_sub(1))
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
