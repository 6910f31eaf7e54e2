//! Profiling aid: loads each pipeline N times up front, then runs only the
//! stack model over the fresh copies (so a profiler sees the model alone).
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: usize = args[0].parse().unwrap();
    let mut ps = Vec::new();
    for f in &args[1..] {
        for _ in 0..n {
            ps.push(rtlint::pipeline::load(std::path::Path::new(f)).unwrap());
        }
    }
    let t = std::time::Instant::now();
    for p in &ps {
        let rec = rtlint::analysis::recursion_report(p);
        std::hint::black_box(rtlint::analysis::stack::stack_report_with(p, &rec));
    }
    eprintln!(
        "model: {:.3} ms per pipeline",
        t.elapsed().as_secs_f64() * 1e3 / ps.len() as f64
    );
}
