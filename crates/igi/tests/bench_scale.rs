//! `igi bench scale` (issue 17): the family it measures grows tenfold per step in the same
//! view, the instanced steps store a hundredth of what the rays can meet, and mesh plus BVH
//! stay within the 64 bytes per stored triangle at every size.

use std::process::Command;

#[test]
fn steps_grow_tenfold_and_stay_within_the_memory_budget() {
    let dir = std::env::temp_dir().join(format!("igi-bench-scale-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let json = dir.join("scale.json");
    let out = Command::new(env!("CARGO_BIN_EXE_igi"))
        .args(["bench", "scale", "--max-exponent", "6", "--reps", "1", "--res", "64x48", "--k", "2"])
        .arg("--json")
        .arg(&json)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    let steps = report["steps"].as_array().unwrap();
    let field = |s: &serde_json::Value, name: &str| s[name].as_f64().unwrap();
    // 10^4, 10^5, 10^6 unique; then 100 instances of 10^5.
    let expected = [(1e4, 1), (1e5, 1), (1e6, 1), (1e7, 100)];
    assert_eq!(steps.len(), expected.len());
    for (step, (triangles, instances)) in steps.iter().zip(expected) {
        let (all, unique) = (field(step, "triangles"), field(step, "unique_triangles"));
        assert!((all / triangles - 1.0).abs() < 0.02, "{step}");
        assert_eq!(step["instances"], instances);
        assert!(
            (unique - 2.0) * instances as f64 - (all - 2.0) < 1.0,
            "{step}: the floor's two triangles aside"
        );
        assert!(field(step, "bytes_per_triangle") <= 64.0, "{step}");
        for kind in ["primary", "shadow"] {
            assert!(field(step, &format!("{kind}_rays")) > 0.0, "{step}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
