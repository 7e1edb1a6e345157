//! A frame holds at most [`FRAME_BYTES_PER_PIXEL`] bytes per pixel and
//! [`FRAME_BYTES_PER_THREAD`] per render thread while it renders (beyond the prepared scene),
//! the figures `igi render` estimates its memory with before it starts (issue 35). A counting global allocator records the peak of live bytes; this binary holds
//! only one test so that nothing else allocates meanwhile.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use igi_render::schedule::frame_renderer::{FRAME_BYTES_PER_PIXEL, FRAME_BYTES_PER_THREAD};
use igi_render::{FrameRenderer, FrameSettings, FrameSource, FrameState, PreparedScene};

struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards to the system allocator unchanged; only counts bytes.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let live = LIVE.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
        PEAK.fetch_max(live, Ordering::Relaxed);
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if new_size >= layout.size() {
            let live = LIVE.fetch_add(new_size - layout.size(), Ordering::Relaxed) + new_size - layout.size();
            PEAK.fetch_max(live, Ordering::Relaxed);
        } else {
            LIVE.fetch_sub(layout.size() - new_size, Ordering::Relaxed);
        }
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

#[test]
fn a_frame_holds_at_most_its_bytes_per_pixel_and_thread() {
    // Matte and glossy scenes, one frame of four rays a pixel (the most points: a pixel across
    // an edge has one per ray) and accumulated frames, at two sizes.
    let threads = 2;
    let cases = [
        ("cornell-box", 4, 1, [384, 256]),
        ("cornell-box", 4, 1, [768, 512]),
        ("cornell-box", 1, 3, [768, 512]),
        ("procedural-room", 4, 2, [384, 256]),
        ("procedural-room", 4, 2, [768, 512]),
    ];
    for (scene, aa, frames, [width, height]) in cases {
        let mut prepared = PreparedScene::new(igi_scene::builtin(scene).unwrap());
        let settings = FrameSettings { width, height, aa, ..FrameSettings::default() };
        let camera = prepared.camera().cloned().expect("the built-ins have cameras");
        let frame = FrameState::new(camera, settings);
        let mut renderer = FrameRenderer::new(threads);
        let before = LIVE.load(Ordering::Relaxed);
        PEAK.store(before, Ordering::Relaxed);
        let out = renderer.render_accumulated(&mut prepared, &frame, frames, &|_, _| {}).unwrap();
        let held = (PEAK.load(Ordering::Relaxed) - before) as u64;
        drop(out);
        let bound =
            threads as u64 * FRAME_BYTES_PER_THREAD + u64::from(width * height) * FRAME_BYTES_PER_PIXEL;
        assert!(
            held <= bound,
            "{scene} {width}x{height}, aa {aa}, {frames} frame(s): {held} bytes, more than {bound}"
        );
    }
}
