//! scratch
#[path = "../benches/triangle_soup/mod.rs"]
#[allow(dead_code)]
mod triangle_soup;
use igi_bvh::*;
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let scene = a.get(1).cloned().unwrap_or("conference/conference.obj".into());
    let threads: usize = a.get(2).map_or(1, |s| s.parse().unwrap());
    let iters: usize = a.get(3).map_or(10, |s| s.parse().unwrap());
    let t = if let Some(n) = scene.strip_prefix("random:") {
        triangle_soup::random_triangles(n.parse().unwrap(), 7)
    } else {
        triangle_soup::load_scene(&scene).unwrap()
    };
    let b = triangle_soup::triangle_bounds(&t);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    let p = BuildParams::default();
    let cpu = || {
        let st = std::fs::read_to_string("/proc/self/stat").unwrap();
        let f: Vec<&str> = st.rsplit(')').next().unwrap().split_whitespace().collect();
        (f[11].parse::<f64>().unwrap() + f[12].parse::<f64>().unwrap()) * 10.0
    };
    let cpu0 = cpu();
    let mut times = vec![];
    let mut bvh = None;
    for _ in 0..iters {
        let s = std::time::Instant::now();
        bvh = Some(pool.install(|| build_binned_sah(&b, &p)));
        times.push(s.elapsed().as_secs_f64() * 1e3);
    }
    let cpu_ms = (cpu() - cpu0) / iters as f64;
    println!("cpu per build {cpu_ms:.1} ms");
    let bvh = bvh.unwrap();
    let nodes = &bvh.nodes;
    let mut cnt = vec![0u32; nodes.len()];
    for i in (0..nodes.len()).rev() {
        cnt[i] = if nodes[i].is_leaf() {
            nodes[i].count
        } else {
            cnt[nodes[i].offset as usize] + cnt[nodes[i].offset as usize + 1]
        };
    }
    let mut hist = vec![0usize; 18];
    let mut big = 0usize;
    let mut bigsum = 0u64;
    let mut smallsum = 0u64;
    for i in 0..nodes.len() {
        let c = cnt[i] as usize;
        if c >= 2 && c <= 16 {
            hist[c] += 1;
            smallsum += c as u64;
        } else if c > 16 {
            big += 1;
            bigsum += c as u64;
        }
    }
    println!("small hist {:?} small visits {smallsum}; big nodes {big} visits {bigsum}", &hist[2..17]);
    let min = times.iter().cloned().fold(f64::MAX, f64::min);
    times.sort_by(f64::total_cmp);
    println!(
        "{scene} {threads}t: median {:.2} ms min {min:.2} ms, nodes {} SAH {:.3} B/tri {:.2} depth {}",
        times[times.len() / 2],
        bvh.nodes.len(),
        bvh.sah_cost(&p),
        bvh.bytes() as f64 / b.len() as f64,
        bvh.depth()
    );
}
