//! The paper's tables for our implementation: `cargo bench -p penumbra-cli --bench paper`.
//! Prints Tables 2 and 4 (counts and the T_d breakdown) for the Data 1 / Data 2 / chair
//! analogues, then the face-count scaling of Data 2. Each bake runs several times; the
//! median is reported. Lighting is left out (`indirect: false`): these are the
//! discontinuity and meshing stages the paper's T_d and T_m measure.

use std::time::Instant;

use penumbra::scenes;
use penumbra::{Progress, Stats};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn run(name: &str, mut s: penumbra::SceneJson, reps: usize) -> (Stats, f64, f64) {
    s.settings.indirect = Some(false);
    let scene = penumbra::scene::validate(&s).expect("valid built-in scene");
    let mut td = Vec::new();
    let mut total = Vec::new();
    let mut last = None;
    for _ in 0..reps {
        let t = Instant::now();
        let b = penumbra::bake(&scene, &Progress::new()).expect("bake");
        total.push(t.elapsed().as_secs_f64());
        let st = b.stats;
        td.push(st.T_sdw + st.T_isr + st.T_idd + st.T_lop + st.T_lit + st.T_div);
        last = Some(st);
    }
    let _ = name;
    (last.unwrap(), median(td), median(total))
}

fn main() {
    let reps = std::env::var("PENUMBRA_BENCH_REPS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(5);
    let cases = [
        ("Data 1", scenes::data1()),
        ("Data 2", scenes::data2(32, 16)),
        ("chair", scenes::chair()),
    ];
    let results: Vec<_> = cases
        .iter()
        .map(|(n, s)| (n, run(n, s.clone(), reps)))
        .collect();
    println!(
        "Table 2 analogue (medians of {reps} runs; threads: {})",
        rayon_threads()
    );
    print!("{:<34}", "");
    for (n, _) in &results {
        print!("{n:>12}");
    }
    println!();
    let row = |label: &str, f: &dyn Fn(&Stats, f64, f64) -> String| {
        print!("{label:<34}");
        for (_, (s, td, tot)) in &results {
            print!("{:>12}", f(s, *td, *tot));
        }
        println!();
    };
    row("receivers before loop split N_f1", &|s, _, _| {
        s.N_f1.to_string()
    });
    row("faces after loop split N_f2", &|s, _, _| s.N_f2.to_string());
    row("discontinuity edges N_d", &|s, _, _| s.N_d.to_string());
    row("elements N_e", &|s, _, _| s.N_e.to_string());
    row("T_d (s)", &|_, td, _| format!("{td:.4}"));
    row("T_m (s)", &|s, _, _| format!("{:.4}", s.T_m));
    row("bake, direct light only (s)", &|_, _, t| format!("{t:.4}"));
    println!("\nTable 4 analogue: where T_d goes (s, last run)");
    row("shadow volumes T_sdw", &|s, _, _| format!("{:.4}", s.T_sdw));
    row("volume ∩ receiver T_isr", &|s, _, _| {
        format!("{:.4}", s.T_isr)
    });
    row("edge ∩ edge T_idd", &|s, _, _| format!("{:.4}", s.T_idd));
    row("loops T_lop", &|s, _, _| format!("{:.4}", s.T_lop));
    row("light relation T_lit", &|s, _, _| format!("{:.4}", s.T_lit));
    row("receiver split T_div", &|s, _, _| format!("{:.4}", s.T_div));

    println!("\nScaling (Data 2 with finer spheres)");
    println!(
        "{:>8} {:>8} {:>10} {:>10} {:>10} {:>10}",
        "seg", "rings", "faces", "T_d (s)", "T_m (s)", "ratio T_d"
    );
    let mut base = None;
    for (seg, rings) in [(32, 16), (64, 32), (101, 51)] {
        let (s, td, _) = run("scale", scenes::data2(seg, rings), reps);
        let b = *base.get_or_insert(td);
        println!(
            "{seg:>8} {rings:>8} {:>10} {td:>10.4} {:>10.4} {:>10.2}",
            s.N_f1,
            s.T_m,
            td / b
        );
    }
}

fn rayon_threads() -> usize {
    std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1)
}
