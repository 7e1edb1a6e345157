//! [`Encoder`]: turns the render loop's newest frame into image files once, for every
//! connection: JPEG for each new frame, PNG (lossless) once the view is still.

use igi_session::{Frame, FrameStats, RenderLoop};
use image::ImageEncoder as _;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};
use tokio::sync::watch;

/// JPEG quality of moving frames.
const JPEG_QUALITY: u8 = 85;
/// No new frame for this long: the view is still, send it losslessly.
const STILL_AFTER: Duration = Duration::from_millis(300);
/// While a still view accumulates, a lossless frame at most this often.
const PNG_INTERVAL: Duration = Duration::from_secs(1);

/// The file format of an encoded frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageKind {
    /// Lossy, for frames that change.
    Jpeg = 0,
    /// Lossless, for a still view.
    Png = 1,
}

/// A frame as it goes out.
#[derive(Debug)]
pub struct EncodedFrame {
    /// The frame's statistics and settings.
    pub stats: FrameStats,
    /// JPEG or PNG.
    pub kind: ImageKind,
    /// The image file.
    pub bytes: Vec<u8>,
}

/// Encodes the frames of a render loop on its own thread until dropped.
#[derive(Debug)]
pub struct Encoder {
    frames: watch::Receiver<Option<Arc<EncodedFrame>>>,
    stop: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Encoder {
    /// Starts encoding the frames of `render_loop`.
    pub fn spawn(render_loop: Arc<RenderLoop>) -> Self {
        let (sender, frames) = watch::channel(None);
        let stop = Arc::new(AtomicBool::new(false));
        let thread = {
            let stop = stop.clone();
            std::thread::Builder::new()
                .name("igi-serve-encoder".into())
                .spawn(move || encode_loop(&render_loop, &sender, &stop))
                .expect("spawning the encoder thread")
        };
        Self { frames, stop, thread: Some(thread) }
    }

    /// A receiver of the newest encoded frame.
    pub fn subscribe(&self) -> watch::Receiver<Option<Arc<EncodedFrame>>> {
        self.frames.clone()
    }
}

impl Drop for Encoder {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

fn encode_loop(
    render_loop: &RenderLoop,
    sender: &watch::Sender<Option<Arc<EncodedFrame>>>,
    stop: &AtomicBool,
) {
    let mut last_id = 0;
    let mut lossless_id = 0;
    let mut last_png = Instant::now();
    while !stop.load(Ordering::SeqCst) {
        match render_loop.latest().wait_newer(last_id, STILL_AFTER) {
            Some(frame) => {
                last_id = frame.stats.id;
                // A still view that keeps accumulating gets a lossless frame now and then.
                let still = frame.stats.accumulated > 1 && last_png.elapsed() >= PNG_INTERVAL;
                let kind = if still { ImageKind::Png } else { ImageKind::Jpeg };
                if let Some(encoded) = encode(&frame, kind) {
                    if kind == ImageKind::Png {
                        (last_png, lossless_id) = (Instant::now(), frame.stats.id);
                    }
                    sender.send_replace(Some(Arc::new(encoded)));
                }
            }
            None => {
                // Nothing new for a while: send the newest frame losslessly, once.
                let Some(frame) = render_loop.latest().get() else { continue };
                if frame.stats.id != lossless_id {
                    lossless_id = frame.stats.id;
                    last_png = Instant::now();
                    if let Some(encoded) = encode(&frame, ImageKind::Png) {
                        sender.send_replace(Some(Arc::new(encoded)));
                    }
                }
            }
        }
    }
}

/// The frame as a JPEG or PNG file (`None`, with a log message, if the encoder fails).
pub fn encode(frame: &Frame, kind: ImageKind) -> Option<EncodedFrame> {
    let (width, height) = (frame.stats.width, frame.stats.height);
    let mut bytes = Vec::new();
    let result = match kind {
        ImageKind::Jpeg => {
            let (w, h) = (u16::try_from(width).ok()?, u16::try_from(height).ok()?);
            jpeg_encoder::Encoder::new(&mut bytes, JPEG_QUALITY)
                .encode(frame.image.srgb8(), w, h, jpeg_encoder::ColorType::Rgb)
                .map_err(|e| e.to_string())
        }
        ImageKind::Png => image::codecs::png::PngEncoder::new(&mut bytes)
            .write_image(frame.image.srgb8(), width, height, image::ExtendedColorType::Rgb8)
            .map_err(|e| e.to_string()),
    };
    match result {
        Ok(()) => Some(EncodedFrame { stats: frame.stats.clone(), kind, bytes }),
        Err(e) => {
            tracing::error!("cannot encode frame {}: {e}", frame.stats.id);
            None
        }
    }
}
