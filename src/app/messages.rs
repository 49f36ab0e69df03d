//! The viewer's messages: a log of errors and notices, newest last, shown as toasts over the
//! window (they never move the layout).

use std::time::Duration;

use eframe::egui;
use egui_notify::ToastLevel;

/// How much a message matters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Level {
    /// Something failed or was refused; its toast stays longer.
    Error,
    /// Something happened that the user should know of.
    Notice,
}

/// One entry of the log.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Message {
    pub level: Level,
    pub text: String,
}

impl Message {
    pub fn error(text: impl Into<String>) -> Self {
        Self {
            level: Level::Error,
            text: text.into(),
        }
    }

    pub fn notice(text: impl Into<String>) -> Self {
        Self {
            level: Level::Notice,
            text: text.into(),
        }
    }

    pub fn is_error(&self) -> bool {
        self.level == Level::Error
    }
}

/// The log and the toasts made from it.
pub struct Messages {
    log: Vec<Message>,
    toasts: egui_notify::Toasts,
    /// How many of `log` the toasts have shown.
    toasted: usize,
}

impl Default for Messages {
    fn default() -> Self {
        Self {
            log: Vec::new(),
            toasts: new_toasts(),
            toasted: 0,
        }
    }
}

impl Messages {
    pub fn push(&mut self, message: Message) {
        self.log.push(message);
    }

    pub fn error(&mut self, text: impl Into<String>) {
        self.push(Message::error(text));
    }

    pub fn notice(&mut self, text: impl Into<String>) {
        self.push(Message::notice(text));
    }

    /// Every message so far, newest last.
    pub fn log(&self) -> &[Message] {
        &self.log
    }

    pub fn last(&self) -> Option<&Message> {
        self.log.last()
    }

    pub fn len(&self) -> usize {
        self.log.len()
    }

    pub fn is_empty(&self) -> bool {
        self.log.is_empty()
    }

    /// Messages not yet shown become toasts: over the panes, bottom right, never moving the
    /// layout; notices go after a few seconds, errors stay longer (hover keeps either).
    pub fn show(&mut self, ctx: &egui::Context) {
        for message in self.log.iter().skip(self.toasted) {
            let text = wrap_words(&message.text, 72);
            // Plain-text marks: egui's default fonts have no emoji for the crate's icons.
            let (level, secs) = match message.level {
                Level::Error => (
                    ToastLevel::Custom("!".into(), egui::Color32::from_rgb(235, 100, 100)),
                    20,
                ),
                Level::Notice => (
                    ToastLevel::Custom("i".into(), egui::Color32::from_rgb(150, 200, 210)),
                    6,
                ),
            };
            self.toasts
                .add(egui_notify::Toast::custom(text, level))
                .closable(false)
                .duration(Some(Duration::from_secs(secs)));
        }
        self.toasted = self.log.len();
        self.toasts.show(ctx);
    }

    /// Takes every toast off the screen at once (the messages stay in the log).
    pub fn clear_toasts(&mut self) {
        self.toasts = new_toasts();
        self.toasted = self.log.len();
    }

    /// The toasts on screen now.
    pub fn toasts_shown(&self) -> usize {
        self.toasts.len()
    }
}

/// The toasts' stack: bottom right, above the status bar, over the panes.
fn new_toasts() -> egui_notify::Toasts {
    egui_notify::Toasts::default()
        .with_anchor(egui_notify::Anchor::BottomRight)
        .with_margin(egui::vec2(12.0, 56.0))
}

/// `text` broken into lines of at most about `width` characters at spaces (a toast does not
/// wrap its text itself).
pub fn wrap_words(text: &str, width: usize) -> String {
    let mut out = String::new();
    let mut line = 0;
    for word in text.split(' ') {
        let n = word.chars().count();
        if line > 0 && line + 1 + n > width {
            out.push('\n');
            line = 0;
        } else if line > 0 {
            out.push(' ');
            line += 1;
        }
        out.push_str(word);
        line += n;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_wrap_at_spaces_only() {
        assert_eq!(wrap_words("a bb ccc dddd", 6), "a bb\nccc\ndddd");
        let long = "x".repeat(30);
        assert_eq!(wrap_words(&long, 10), long);
        assert_eq!(wrap_words("", 10), "");
    }
}
