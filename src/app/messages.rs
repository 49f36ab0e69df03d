//! The viewer's messages: a log of errors and notices, newest last; each new one shows once as
//! a toast in the bottom-right corner of the render pane (never moving the layout, never more than
//! [`MAX_TOASTS`] at once, each at most [`TOAST_LINES`] lines), and the whole log, with each
//! message's details, is in the Messages window (View › Messages).
//!
//! The toasts are drawn here rather than by a toast crate: the crates count a toast's time down
//! frame by frame, so the viewer would repaint continuously while one is shown. These expire by
//! the clock, and the viewer asks for one frame when the next one goes.

use std::time::{Duration, Instant};

use eframe::egui;

/// How much a message matters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Level {
    /// Something failed or was refused; its toast stays longer.
    Error,
    /// Something happened that the user should know of.
    Notice,
}

/// One entry of the log: a sentence, and the details behind it (a loader's notes, say), which
/// the toast only counts and the Messages window lists.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Message {
    pub level: Level,
    pub text: String,
    pub details: Vec<String>,
}

impl Message {
    pub fn error(text: impl Into<String>) -> Self {
        Self {
            level: Level::Error,
            text: text.into(),
            details: Vec::new(),
        }
    }

    pub fn notice(text: impl Into<String>) -> Self {
        Self {
            level: Level::Notice,
            text: text.into(),
            details: Vec::new(),
        }
    }

    /// The message with `details` behind it.
    pub fn with_details(mut self, details: Vec<String>) -> Self {
        self.details = details;
        self
    }

    pub fn is_error(&self) -> bool {
        self.level == Level::Error
    }

    /// Whether the message or one of its details contains `text`.
    pub fn mentions(&self, text: &str) -> bool {
        self.text.contains(text) || self.details.iter().any(|d| d.contains(text))
    }
}

/// The most toasts on screen at once: a new one pushes the oldest off (it stays in the log).
pub const MAX_TOASTS: usize = 3;
/// The most lines of a toast's text; a longer message ends in "…" (the log has it whole).
pub const TOAST_LINES: usize = 4;
/// Width of a toast's text, in points.
const TOAST_WIDTH: f32 = 340.0;

/// A message on screen until `until`.
#[derive(Clone, Copy, Debug)]
struct Toast {
    /// Its index in the log.
    index: usize,
    until: Instant,
}

/// The log, the toasts made from it and the Messages window.
#[derive(Debug, Default)]
pub struct Messages {
    log: Vec<Message>,
    toasts: Vec<Toast>,
    /// How many of `log` have had their toast.
    toasted: usize,
    /// The Messages window is open.
    pub window: bool,
    /// Where this frame's toasts go: the render pane, set by it each frame (so they cover the
    /// image for a few seconds rather than the tree's panes or the status bar). `None`, or a
    /// pane narrower than a toast: the window's bottom-right corner.
    pub corner: Option<egui::Rect>,
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

    /// Messages not yet shown become toasts; expired toasts go. Asks for a frame when the next
    /// toast expires, and for none otherwise.
    pub fn show(&mut self, ctx: &egui::Context) {
        let corner = self.corner.take();
        let now = Instant::now();
        for index in self.toasted..self.log.len() {
            let secs = match self.log[index].level {
                Level::Error => 20,
                Level::Notice => 6,
            };
            self.toasts.push(Toast {
                index,
                until: now + Duration::from_secs(secs),
            });
        }
        self.toasted = self.log.len();
        self.toasts.retain(|t| t.until > now);
        let excess = self.toasts.len().saturating_sub(MAX_TOASTS);
        self.toasts.drain(..excess);
        if self.toasts.is_empty() {
            return;
        }
        let mut dismissed = None;
        let mut hovered = false;
        let mut open_log = false;
        let area = egui::Area::new(egui::Id::unique("raytree toasts"))
            .order(egui::Order::Foreground)
            .interactable(true);
        let area = match corner {
            Some(pane) if pane.width() >= TOAST_WIDTH + 64.0 => area
                .pivot(egui::Align2::RIGHT_BOTTOM)
                .fixed_pos(pane.right_bottom() - egui::vec2(10.0, 10.0)),
            _ => area.anchor(egui::Align2::RIGHT_BOTTOM, egui::vec2(-12.0, -56.0)),
        };
        area.show(ctx, |ui| {
            ui.set_max_width(TOAST_WIDTH + 40.0);
            for (k, toast) in self.toasts.iter().enumerate().rev() {
                let message = &self.log[toast.index];
                let frame = egui::Frame::popup(ui.style()).show(ui, |ui| {
                    ui.set_width(TOAST_WIDTH + 24.0);
                    ui.horizontal_top(|ui| {
                        let (mark, colour) = match message.level {
                            Level::Error => ("!", egui::Color32::from_rgb(235, 100, 100)),
                            Level::Notice => ("i", egui::Color32::from_rgb(150, 200, 210)),
                        };
                        ui.label(egui::RichText::new(mark).strong().color(colour));
                        ui.vertical(|ui| {
                            ui.set_max_width(TOAST_WIDTH);
                            let mut job = egui::text::LayoutJob::simple(
                                message.text.clone(),
                                egui::TextStyle::Body.resolve(ui.style()),
                                ui.visuals().text_color(),
                                TOAST_WIDTH,
                            );
                            job.wrap.max_rows = TOAST_LINES;
                            ui.label(job);
                            if !message.details.is_empty() {
                                let n = message.details.len();
                                let more =
                                    format!("{}: View › Messages", crate::plural::count(n, "note"));
                                if ui.small_button(more).clicked() {
                                    open_log = true;
                                }
                            }
                        });
                        if ui.small_button("×").on_hover_text("dismiss").clicked() {
                            dismissed = Some(k);
                        }
                    });
                });
                hovered |= frame.response.contains_pointer();
            }
        });
        if let Some(k) = dismissed {
            self.toasts.remove(k);
        }
        if open_log {
            self.window = true;
        }
        // A toast under the pointer stays until the pointer leaves.
        if hovered {
            let at_least = now + Duration::from_secs(2);
            for t in &mut self.toasts {
                t.until = t.until.max(at_least);
            }
        }
        if let Some(next) = self.toasts.iter().map(|t| t.until).min() {
            ctx.request_repaint_after(next.saturating_duration_since(now));
        }
    }

    /// The Messages window: the whole log, newest first, each message's details under it.
    pub fn log_window(&mut self, ctx: &egui::Context) {
        let mut open = self.window;
        egui::Window::new("Messages")
            .open(&mut open)
            .default_size([520.0, 360.0])
            .show(ctx, |ui| {
                if self.log.is_empty() {
                    ui.weak("no messages yet");
                    return;
                }
                egui::ScrollArea::vertical().show(ui, |ui| {
                    for (i, m) in self.log.iter().enumerate().rev() {
                        let mark = if m.is_error() { "error" } else { "notice" };
                        ui.horizontal_top(|ui| {
                            ui.weak(mark);
                            ui.add(egui::Label::new(&m.text).wrap());
                        });
                        if !m.details.is_empty() {
                            egui::CollapsingHeader::new(crate::plural::count(
                                m.details.len(),
                                "note",
                            ))
                            .id_salt(("message details", i))
                            .default_open(i + 1 == self.log.len())
                            .show(ui, |ui| {
                                for d in &m.details {
                                    ui.add(egui::Label::new(format!("• {d}")).wrap());
                                }
                            });
                        }
                        ui.separator();
                    }
                });
            });
        self.window = open;
    }

    /// Takes every toast off the screen at once (the messages stay in the log).
    pub fn clear_toasts(&mut self) {
        self.toasts.clear();
        self.toasted = self.log.len();
    }

    /// The toasts on screen now.
    pub fn toasts_shown(&self) -> usize {
        self.toasts.len()
    }
}
