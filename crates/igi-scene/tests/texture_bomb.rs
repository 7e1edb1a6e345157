//! A texture "bomb" (a small PNG that decodes to a huge image) referenced many ways cannot
//! make a load take more memory than one compact decode, and a scene-wide budget bounds what
//! the textures keep.
//!
//! A counting global allocator records the peak of live bytes; this binary holds only one test
//! so that nothing else allocates meanwhile.

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

use common::textured_triangle_gltf;
use igi_scene::{LoadOptions, Texels, load_with};
use image::ImageEncoder;
use image::codecs::png::{CompressionType, FilterType, PngEncoder};

struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

fn grow(bytes: usize) {
    let live = LIVE.fetch_add(bytes, Ordering::Relaxed) + bytes;
    PEAK.fetch_max(live, Ordering::Relaxed);
}

// SAFETY: forwards to the system allocator unchanged; only counts bytes.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        grow(layout.size());
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        grow(layout.size());
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if new_size >= layout.size() {
            grow(new_size - layout.size());
        } else {
            LIVE.fetch_sub(layout.size() - new_size, Ordering::Relaxed);
        }
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

const MIB: usize = 1 << 20;
/// The bomb: 8192 × 8192 black RGB pixels, a PNG of a few hundred KB that decodes to 256 MiB
/// of 8-bit RGBA (1 GiB as linear floats, which the loaders used to keep per reference).
const SIDE: u32 = 8192;
const DECODED: usize = SIDE as usize * SIDE as usize * 4;

/// A scene that refers to `bomb.png` eight ways: an OBJ's two materials as colour map and as
/// bump map under three spellings of its path, and a glTF file using it in four slots.
fn write_scene(dir: &Path) {
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    let mut png = Vec::new();
    let encoder = PngEncoder::new_with_quality(&mut png, CompressionType::Fast, FilterType::NoFilter);
    let black = vec![0u8; SIDE as usize * SIDE as usize * 3];
    encoder.write_image(&black, SIDE, SIDE, image::ExtendedColorType::Rgb8).unwrap();
    drop(black);
    assert!(png.len() < 2 * MIB, "the bomb is small: {} bytes", png.len());
    std::fs::write(dir.join("bomb.png"), &png).unwrap();
    std::fs::write(
        dir.join("bomb.mtl"),
        "newmtl a\nmap_Kd bomb.png\nmap_bump ./bomb.png\nnewmtl b\nmap_Kd sub/../bomb.png\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("bomb.obj"),
        "mtllib bomb.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvt 1 1\n\
         usemtl a\nf 1/1 2/2 3/3\nusemtl b\nf 2/2 4/4 3/3\n",
    )
    .unwrap();
    let material = r#"{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0},
                                                "metallicRoughnessTexture": {"index": 0}},
                       "normalTexture": {"index": 0}, "emissiveTexture": {"index": 0},
                       "emissiveFactor": [1, 1, 1]}"#;
    let gltf = textured_triangle_gltf("bomb.png", &[material]);
    std::fs::write(dir.join("bomb.gltf"), gltf).unwrap();
    std::fs::write(
        dir.join("bomb.toml"),
        "[[mesh]]\nfile = \"bomb.obj\"\n[[mesh]]\nfile = \"./bomb.gltf\"\n[[mesh]]\nfile = \"bomb.obj\"\n",
    )
    .unwrap();
}

/// Loads `bomb.toml` with `budget` and returns the storage and width of each texture, the peak
/// of live bytes during the load and the warnings.
fn load(dir: &Path, budget: u64) -> (Vec<(usize, u32)>, usize, Vec<String>) {
    let before = LIVE.load(Ordering::Relaxed);
    PEAK.store(before, Ordering::Relaxed);
    let (scene, report) = load_with(&dir.join("bomb.toml"), &LoadOptions { texture_budget: budget })
        .unwrap_or_else(|e| panic!("{e}"));
    let peak = PEAK.load(Ordering::Relaxed) - before;
    let bytes = scene.texel_bytes();
    assert!(bytes <= budget, "{bytes} bytes of texels over a budget of {budget}");
    let storage = scene
        .textures
        .iter()
        .map(|t| match &t.image.texels {
            Texels::Rgba8 { texels, .. } => (texels.as_ptr() as usize, t.image.width),
            other => panic!("8-bit images stay 8-bit: {other:?}"),
        })
        .collect();
    (storage, peak, report.warnings)
}

/// The texel bytes of `bomb.toml` loaded with the default budget.
fn scene_bytes(dir: &Path) -> u64 {
    igi_scene::load(dir.join("bomb.toml")).unwrap().texel_bytes()
}

#[test]
fn a_bomb_referenced_eight_ways_is_decoded_once_compactly_and_within_the_budget() {
    let dir = std::env::temp_dir().join(format!("igi-texture-bomb-{}", std::process::id()));
    write_scene(&dir);

    // Default budget: one decode, 4 bytes per texel, shared by a colour and a data view.
    let (storage, peak, warnings) = load(&dir, igi_scene::DEFAULT_TEXTURE_BUDGET);
    assert_eq!(storage.len(), 2, "one texture per colour space: {warnings:?}");
    assert_eq!(storage[0], storage[1], "both views read the same texels");
    assert_eq!(storage[0].1, SIDE);
    assert_eq!(scene_bytes(&dir), DECODED as u64, "4 bytes per texel, counted once");
    assert!(peak < DECODED + 32 * MIB, "peak {} MiB for a {} MiB image", peak / MIB, DECODED / MIB);

    // A 48 MiB budget: the image (341 MiB with its mipmap) is halved twice, to 16 MiB.
    let (storage, peak, warnings) = load(&dir, 48 << 20);
    assert_eq!(storage.len(), 2);
    assert_eq!(storage[0].1, SIDE / 4);
    assert!(
        warnings.iter().any(|w| w.contains("texture budget") && w.contains("downscaled to 2048x2048")),
        "{warnings:?}"
    );
    // The full-size decode and its first half-size level are live together, nothing more.
    assert!(peak < DECODED + DECODED / 4 + 32 * MIB, "peak {} MiB", peak / MIB);

    // A budget too small for even one texel (4 bytes, 5 with a mipmap): the textures are
    // skipped with a warning and the load still succeeds.
    let (storage, _, warnings) = load(&dir, 4);
    assert!(storage.is_empty());
    assert!(warnings.iter().any(|w| w.contains("does not fit")), "{warnings:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}
