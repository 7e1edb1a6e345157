//! `igi serve`: a browser viewer of an [`igi_session::Session`]. An axum server serves one
//! page (embedded in the binary, no build step), one WebSocket and the list of scenes it may
//! open; the page draws the frames on a canvas and sends the user's input back. Nothing else
//! is served.
//!
//! # Wire protocol (`GET /ws`)
//!
//! Client → server: text messages of JSON, one [`ClientMessage`] each:
//! `{"id": 17, "input": {"type": "drag", "dx": 4, "dy": 0, "button": "primary"}}`, where
//! `input` is an [`igi_session::Input`] and `id` an optional number of the client's choosing.
//! A message that is not such JSON, a binary message, or one longer than
//! [`MAX_MESSAGE_BYTES`] closes that connection (and nothing else), with the close code
//! RFC 6455 gives to the fault: 1002 a broken frame, 1003 a binary message, 1007 text that is
//! not UTF-8 or not an input, 1009 a message too long.
//!
//! Server → client: binary messages, one per frame: one byte of image kind (0 JPEG, 1 PNG),
//! a little-endian `u32` length n, n bytes of JSON ([`FrameHeader`]: the frame's statistics
//! and settings, the highest input `id` of this connection the frame includes, refused
//! settings), then the image file. Frames are JPEG while things change and PNG (lossless)
//! once the view is still. Newest frame wins: a connection is sent the newest frame when its
//! previous send has completed, so a slow client gets fewer frames and nothing queues up.
//!
//! Settings a client sends are checked on its connection: invalid ones, and ones whose frame
//! would cost more than the server's [`FrameBudget`], are refused with the reason in the
//! `errors` of that connection's next frame. So are the inputs the session refuses (a scene
//! that does not open, a view or light source the scene does not have): the reason goes to
//! the connection that sent them, at once with the newest frame, at most
//! [`igi_session::refusals::MAX_KEPT`] reasons of at most
//! [`igi_session::refusals::MAX_CHARS`] characters waiting for a client that reads none.
//!
//! Modules: [`encoder`] (frames to JPEG/PNG once for all connections), [`connection`] (one
//! WebSocket), [`budget`] (the most a frame may cost), [`places`] (how many connections may be
//! open, and who gives way), [`server`] (routes, start and shutdown).

pub mod access;
pub mod budget;
pub mod connection;
pub mod encoder;
pub mod places;
pub mod server;

pub use budget::FrameBudget;
pub use connection::{ClientMessage, FrameHeader, MAX_MESSAGE_BYTES};
pub use server::{Limits, bind, run, serve};
