//! Counts in headers cannot make a loader allocate more than the input backs: a small file
//! that claims billions of elements is rejected without a large allocation.
//!
//! A counting global allocator records the largest single allocation; this binary holds only
//! one test so that nothing else allocates meanwhile.

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use common::gltf_document;
use igi_scene::LoadReport;

struct Largest;

static LARGEST: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards to the system allocator unchanged; only records sizes.
unsafe impl GlobalAlloc for Largest {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        LARGEST.fetch_max(layout.size(), Ordering::Relaxed);
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        LARGEST.fetch_max(new_size, Ordering::Relaxed);
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Largest = Largest;

/// Runs `load` and returns the largest allocation it made.
fn largest_allocation(load: impl FnOnce() -> bool) -> usize {
    LARGEST.store(0, Ordering::Relaxed);
    assert!(load(), "the lying input must be rejected");
    LARGEST.load(Ordering::Relaxed)
}

#[test]
fn lying_counts_do_not_allocate() {
    const LIMIT: usize = 1 << 20;
    let mut report = LoadReport::default();

    let header = |format: &str, count: &str| {
        format!(
            "ply\nformat {format} 1.0\nelement vertex {count}\nproperty float x\nproperty float y\nproperty float z\nelement face {count}\nproperty list uint int vertex_indices\nend_header\n"
        )
    };
    for format in ["binary_little_endian", "binary_big_endian", "ascii"] {
        for count in ["4000000000", "18446744073709551615", "3"] {
            let mut bytes = header(format, count).into_bytes();
            bytes.extend([0xff; 64]);
            let largest = largest_allocation(|| {
                igi_scene::parse_mesh(igi_scene::MeshFormat::Ply, &bytes, "lie.ply", None, &mut report)
                    .is_err()
            });
            assert!(largest < LIMIT, "{format} {count}: {largest} bytes");
        }
    }

    let (json, _) = gltf_document(&[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], &[0, 1, 2], true);
    let lies = [
        json.replacen(r#""count":3"#, r#""count":4000000000"#, 1),
        // No buffer view: four billion zeros with one sparse value, all the file's data.
        json.replacen(
            r#"{"bufferView":0,"componentType":5126,"count":3,"#,
            r#"{"componentType":5126,"count":4294967295,"sparse":{"count":1,"indices":{"bufferView":1,"componentType":5123},"values":{"bufferView":0}},"#,
            1,
        ),
        json.replacen(r#""byteLength":44"#, r#""byteLength":1000000000000"#, 1),
        json.replacen(r#""byteLength":36"#, r#""byteLength":4000000000"#, 1),
    ];
    for lie in lies {
        let largest = largest_allocation(|| {
            igi_scene::parse_mesh(igi_scene::MeshFormat::Gltf, lie.as_bytes(), "lie.gltf", None, &mut report)
                .is_err()
        });
        assert!(largest < LIMIT, "{lie}: {largest} bytes");
    }
    // 20,000 primitives over one accessor of 300,000 vertices (3.6 MB of data): each would be
    // read into the mesh, 7 GB in all; refused before the first, so nothing beyond the file's
    // own buffer is allocated.
    let positions: Vec<[f32; 3]> = (0..300_000).map(|i| [i as f32, 0.0, 0.0]).collect();
    let (json, _) = gltf_document(&positions, &[0, 1, 2], true);
    let primitive = r#"{"attributes":{"POSITION":0},"indices":1}"#;
    let many = json.replacen(primitive, &vec![primitive; 20_000].join(","), 1);
    let largest = largest_allocation(|| {
        igi_scene::parse_mesh(igi_scene::MeshFormat::Gltf, many.as_bytes(), "many.gltf", None, &mut report)
            .is_err()
    });
    assert!(largest < 4 * many.len(), "primitives sharing an accessor: {largest} bytes");
    // Key times that claim a billion keys: the channel is skipped before they are read.
    let animated = common::lying_key_times();
    let largest = largest_allocation(|| {
        let scene = igi_scene::parse_mesh(
            igi_scene::MeshFormat::Gltf,
            animated.as_bytes(),
            "lie.gltf",
            None,
            &mut report,
        );
        scene.is_ok_and(|scene| scene.animation.is_empty())
    });
    assert!(largest < LIMIT, "sparse key times: {largest} bytes");
    let mut glb = b"glTF\x02\0\0\0\xff\xff\xff\x7f\xf0\xff\xff\x7fJSON{}".to_vec();
    glb.extend([b' '; 32]);
    let largest = largest_allocation(|| {
        igi_scene::parse_mesh(igi_scene::MeshFormat::Gltf, &glb, "lie.glb", None, &mut report).is_err()
    });
    assert!(largest < LIMIT, "GLB chunk length: {largest} bytes");
}
