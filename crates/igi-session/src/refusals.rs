//! [`Refusals`]: what one viewer is owed an answer about: its inputs that the session refused
//! (a view, light or scene it does not have, settings out of range) and frames that failed.
//! Each viewer has its own, so a refusal reaches the viewer that caused it and no other
//! (issue 35).
//!
//! Bounded whether or not the viewer takes them: at most [`MAX_KEPT`] messages (a newer one
//! pushes the oldest out) of at most [`MAX_CHARS`] characters each. The render loop holds only
//! a weak reference to a viewer's messages, with each of its inputs waiting to be handled, so
//! dropping the [`Refusals`] (a closed connection) frees them, and a refusal for a viewer that
//! has gone is not kept at all.

use std::collections::VecDeque;
use std::sync::{Arc, Mutex, MutexGuard, Weak};

/// The most messages kept for a viewer that has not taken them.
pub const MAX_KEPT: usize = 8;
/// The longest message kept, in characters; a longer one is cut and ends in "…".
pub const MAX_CHARS: usize = 400;
/// The most characters of a name a message quotes ([`quote_name`]): a browser may send names
/// of 16 KiB.
pub const MAX_NAME_CHARS: usize = 80;

/// One viewer's refusal messages, made by [`crate::RenderLoop::refusals`]; the viewer passes
/// it with each input it sends ([`crate::RenderLoop::send`]).
pub struct Refusals {
    mailbox: Arc<Mailbox>,
}

impl std::fmt::Debug for Refusals {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Refusals").field("messages", &*self.mailbox.lock()).finish_non_exhaustive()
    }
}

/// What the render loop reaches a viewer's messages through (weakly).
pub(crate) struct Mailbox {
    messages: Mutex<VecDeque<String>>,
    /// Tells the viewer a message came: it may wait for a frame that is not coming (a still
    /// view renders none after a refusal).
    wake: Box<dyn Fn() + Send + Sync>,
}

impl Mailbox {
    fn lock(&self) -> MutexGuard<'_, VecDeque<String>> {
        self.messages.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Keeps `message`, cut to [`MAX_CHARS`], dropping the oldest beyond [`MAX_KEPT`], and
    /// wakes the viewer.
    pub(crate) fn push(&self, message: &str) {
        {
            let mut messages = self.lock();
            if messages.len() == MAX_KEPT {
                messages.pop_front();
            }
            messages.push_back(cut(message, MAX_CHARS));
        }
        (self.wake)();
    }
}

impl Refusals {
    /// Empty, calling `wake` after each message that comes.
    pub(crate) fn new(wake: impl Fn() + Send + Sync + 'static) -> Self {
        Self { mailbox: Arc::new(Mailbox { messages: Mutex::default(), wake: Box::new(wake) }) }
    }

    /// The reference the render loop keeps: it lets the messages go with the viewer.
    pub(crate) fn downgrade(&self) -> Weak<Mailbox> {
        Arc::downgrade(&self.mailbox)
    }

    /// Tells the viewer why it refused something itself (a connection refuses settings over
    /// its budget before they reach the session), within the same bounds.
    pub fn push(&self, message: &str) {
        self.mailbox.push(message);
    }

    /// The messages since the last call, oldest first.
    pub fn take(&self) -> Vec<String> {
        self.mailbox.lock().drain(..).collect()
    }

    /// The messages kept and their characters: at most [`MAX_KEPT`] and [`MAX_KEPT`] ×
    /// [`MAX_CHARS`] (the message "…" counted as one).
    pub fn kept(&self) -> (usize, usize) {
        let messages = self.mailbox.lock();
        (messages.len(), messages.iter().map(|m| m.chars().count()).sum())
    }
}

/// `text`, or its first `max` - 1 characters and "…" if it is longer.
fn cut(text: &str, max: usize) -> String {
    match text.char_indices().nth(max) {
        None => text.to_string(),
        Some(_) => {
            let end = text.char_indices().nth(max - 1).map_or(text.len(), |(i, _)| i);
            format!("{}…", &text[..end])
        }
    }
}

/// `name` in quotes for a message, cut to [`MAX_NAME_CHARS`] with its length in bytes said,
/// so that what the message says after a long name still fits in [`MAX_CHARS`].
pub fn quote_name(name: &str) -> String {
    match name.chars().nth(MAX_NAME_CHARS) {
        None => format!("{name:?}"),
        Some(_) => format!("{:?} ({} bytes)", cut(name, MAX_NAME_CHARS), name.len()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_messages_and_names_are_cut_at_a_character() {
        assert_eq!(cut("abc", 3), "abc");
        assert_eq!(cut("abcd", 3), "ab…");
        assert_eq!(cut("ééééé", 4), "ééé…");
        assert_eq!(quote_name("statue"), "\"statue\"");
        let long = "x".repeat(15_000);
        let quoted = quote_name(&long);
        assert!(quoted.starts_with("\"xxx") && quoted.ends_with("…\" (15000 bytes)"), "{quoted}");
        assert_eq!(quoted.chars().count(), MAX_NAME_CHARS + 2 + " (15000 bytes)".len());
    }

    #[test]
    fn a_viewer_that_never_takes_keeps_the_newest_few() {
        let refusals = Refusals::new(|| {});
        for i in 0..10_000 {
            refusals.push(&format!("{i} {}", "y".repeat(15_000)));
        }
        let (count, chars) = refusals.kept();
        assert_eq!(count, MAX_KEPT);
        assert!(chars <= MAX_KEPT * MAX_CHARS, "{chars}");
        let taken = refusals.take();
        assert!(taken[0].starts_with("9992 ") && taken[MAX_KEPT - 1].starts_with("9999 "));
        assert_eq!(refusals.kept(), (0, 0));
    }
}
