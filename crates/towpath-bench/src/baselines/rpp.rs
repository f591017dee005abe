//! Seed 004's comparison (Table I) on generated instances of its ten sample-data sizes.

use std::time::Duration;

use towpath_baselines::{solve_with, AcoParams, BaselineParams, GaParams, SolverName};
use towpath_coverage::{tewolde_sheng_like, RppModel, TABLE_I_SIZES};
use towpath_seq::SolveOptions;

use super::Args;
use crate::stats::{median, ms};

/// One row of seed 004's Table I: path lengths (m) and ACO2's time (s; `None` is "< 0.01").
struct PaperRow {
    aco1: f64,
    aco2: f64,
    ga: f64,
    aco2_s: Option<f64>,
}

const fn row(aco1: f64, aco2: f64, ga: f64, aco2_s: Option<f64>) -> PaperRow {
    PaperRow { aco1, aco2, ga, aco2_s }
}

/// Seed 004 Table I.
const PAPER: [PaperRow; 10] = [
    row(16.0, 16.0, 16.0, None),
    row(21.12, 21.12, 21.12, Some(0.01)),
    row(32.56, 32.56, 34.45, Some(0.10)),
    row(38.53, 38.53, 39.06, Some(0.25)),
    row(63.72, 63.72, 68.71, Some(0.51)),
    row(68.42, 67.06, 73.94, Some(0.93)),
    row(83.45, 83.28, 91.66, Some(1.57)),
    row(87.11, 86.87, 95.66, Some(1.89)),
    row(89.66, 89.49, 100.62, Some(2.41)),
    row(102.10, 102.10, 115.48, Some(3.56)),
];

const SEEDS: [SolverName; 3] = [SolverName::Ga, SolverName::Aco1, SolverName::Aco2];

struct SizeResult {
    v: usize,
    r: usize,
    /// Per solver (GA, ACO1, ACO2, then towpath at each time limit): every (length, seconds).
    runs: Vec<Vec<(f64, f64)>>,
    reference: Vec<f64>,
    /// Per towpath limit, per instance: towpath median / best seed-solver median.
    ratios: Vec<Vec<f64>>,
    /// Per towpath limit: instances where towpath's worst run ≤ the seed solvers' best run.
    wins: Vec<usize>,
    /// Per towpath limit: instances where towpath's median run ≤ the best seed solver's median.
    median_wins: Vec<usize>,
    instances: usize,
    /// Per instance (GA median − ACO2 median) / ACO2 median.
    aco_vs_ga: Vec<f64>,
}

/// Runs the table and returns its Markdown.
pub fn run(args: &Args) -> anyhow::Result<String> {
    let sizes: Vec<(usize, usize)> = if args.quick { TABLE_I_SIZES[..3].to_vec() } else { TABLE_I_SIZES.to_vec() };
    let seeds = if args.quick { 2 } else { args.seeds.max(1) };
    let runs = if args.quick { 1 } else { args.runs.max(1) };
    let params = BaselineParams { ga: GaParams::table_i(), aco: AcoParams::default(), ..BaselineParams::default() };
    let mut results = Vec::new();
    for &(v, r) in &sizes {
        let limits = &args.towpath_ms;
        let mut res = SizeResult {
            v,
            r,
            runs: vec![Vec::new(); 3 + limits.len()],
            reference: Vec::new(),
            ratios: vec![Vec::new(); limits.len()],
            wins: vec![0; limits.len()],
            median_wins: vec![0; limits.len()],
            instances: 0,
            aco_vs_ga: Vec::new(),
        };
        for s in 1..=seeds {
            let model = RppModel::new(tewolde_sheng_like(r, s)?)?;
            let p = model.problem();
            let mut inst: Vec<Vec<(f64, f64)>> = vec![Vec::new(); 3 + limits.len()];
            for k in 1..=runs {
                for (i, &name) in SEEDS.iter().enumerate() {
                    let opts = SolveOptions { time_limit: None, seed: k, threads: 1, ..SolveOptions::default() };
                    let rep = solve_with(name, p, &opts, &params)?;
                    inst[i].push((rep.solution.cost, rep.elapsed.as_secs_f64()));
                }
                for (j, &limit) in limits.iter().enumerate() {
                    let opts = SolveOptions {
                        time_limit: Some(Duration::from_secs_f64(limit / 1e3)),
                        seed: k,
                        threads: 1,
                        ..SolveOptions::default()
                    };
                    let rep = solve_with(SolverName::Towpath, p, &opts, &params)?;
                    inst[3 + j].push((rep.solution.cost, rep.elapsed.as_secs_f64()));
                }
            }
            let best_seed = inst[..3].iter().flatten().map(|x| x.0).fold(f64::INFINITY, f64::min);
            let lens = |i: usize| inst[i].iter().map(|x| x.0).collect::<Vec<_>>();
            let best_seed_median = (0..3).map(|i| median(&lens(i))).fold(f64::INFINITY, f64::min);
            for j in 0..limits.len() {
                let towpath_worst = inst[3 + j].iter().map(|x| x.0).fold(f64::NEG_INFINITY, f64::max);
                let towpath_median = median(&lens(3 + j));
                res.ratios[j].push(towpath_median / best_seed_median);
                if towpath_median <= best_seed_median + 1e-9 {
                    res.median_wins[j] += 1;
                }
                if towpath_worst <= best_seed + 1e-9 {
                    res.wins[j] += 1;
                }
            }
            res.aco_vs_ga.push((median(&lens(0)) - median(&lens(2))) / median(&lens(2)));
            res.instances += 1;
            if args.reference_ms > 0.0 {
                let opts = SolveOptions {
                    time_limit: Some(Duration::from_secs_f64(args.reference_ms / 1e3)),
                    seed: 1,
                    threads: 1,
                    ..SolveOptions::default()
                };
                let rep = solve_with(SolverName::Towpath, p, &opts, &params)?;
                let all_best = inst.iter().flatten().map(|x| x.0).fold(rep.solution.cost, f64::min);
                res.reference.push(all_best);
            }
            for (i, v) in inst.into_iter().enumerate() {
                res.runs[i].extend(v);
            }
        }
        eprintln!("Tewolde & Sheng size {v} v / {r} re done");
        results.push(res);
    }
    Ok(markdown(args, &results, seeds, runs))
}

fn markdown(args: &Args, results: &[SizeResult], seeds: u64, runs: u64) -> String {
    let limits = &args.towpath_ms;
    let lim = |l: f64| format!("{l} ms");
    let faster = |base: f64, t: f64| {
        if t <= base {
            format!("{:.1}× faster", base / t)
        } else {
            format!("{:.1}× slower", t / base)
        }
    };
    let mut s = String::new();
    s.push_str("### Tewolde & Sheng (2008): GA vs ACO vs towpath on the open rural postman problem\n\n");
    s.push_str(&format!(
        "Instances: `tewolde_sheng_like(R, seed)` (towpath-coverage), shaped like the paper's Table I sample data \
         (|V| = 2|R|, patch paths as required edges, lengths in metres), {seeds} instances per size, {runs} \
         run(s) per instance and solver (solver seeds 1..{runs}). GA at Table I's settings (1000 generations, \
         population 200, crossover rate 0.2, mutation rate 0.05); ACO1/ACO2 at §VI-B's (α 1, β 5, ρ 0.5, Q 100, \
         10 cycles); towpath's solver with time limits of {}. Lengths and times are medians over all runs; \
         \"≤ best\" counts the instances where towpath's *worst* run is no longer than the best run of GA, ACO1 \
         and ACO2; \"/ best\" is the median over instances of towpath's median length over the best seed \
         solver's median length.{}\n\n",
        limits.iter().map(|&l| lim(l)).collect::<Vec<_>>().join(" and "),
        if args.reference_ms > 0.0 {
            format!(" \"Best known\" is the best of all these runs and one {} ms towpath run.", args.reference_ms)
        } else {
            String::new()
        }
    ));
    s.push_str("| data set | GA (m) | ACO1 (m) | ACO2 (m) | best known (m) |");
    for &l in limits {
        s.push_str(&format!(" towpath [{}] (m) | / best | ≤ best |", lim(l)));
    }
    s.push_str(" GA ms | ACO1 ms | ACO2 ms |");
    for &l in limits {
        s.push_str(&format!(" towpath [{}] ms |", lim(l)));
    }
    s.push_str("\n|---|---:|---:|---:|---:|");
    for _ in limits {
        s.push_str("---:|---:|---:|");
    }
    s.push_str("---:|---:|---:|");
    for _ in limits {
        s.push_str("---:|");
    }
    s.push('\n');
    let med = |v: &[(f64, f64)], f: fn(&(f64, f64)) -> f64| median(&v.iter().map(f).collect::<Vec<_>>());
    let mut total_wins = vec![0; limits.len()];
    let mut total_median_wins = vec![0; limits.len()];
    let mut total = 0;
    for (i, r) in results.iter().enumerate() {
        total += r.instances;
        s.push_str(&format!(
            "| #{} ({} v, {} re) | {:.2} | {:.2} | {:.2} | {} |",
            i + 1,
            r.v,
            r.r,
            med(&r.runs[0], |x| x.0),
            med(&r.runs[1], |x| x.0),
            med(&r.runs[2], |x| x.0),
            if r.reference.is_empty() { "–".to_string() } else { format!("{:.2}", median(&r.reference)) },
        ));
        for j in 0..limits.len() {
            total_wins[j] += r.wins[j];
            total_median_wins[j] += r.median_wins[j];
            s.push_str(&format!(
                " {:.2} | {:.4} | {}/{} |",
                med(&r.runs[3 + j], |x| x.0),
                median(&r.ratios[j]),
                r.wins[j],
                r.instances
            ));
        }
        for k in 0..3 {
            s.push_str(&format!(" {} |", ms(med(&r.runs[k], |x| x.1))));
        }
        for j in 0..limits.len() {
            s.push_str(&format!(" {} |", ms(med(&r.runs[3 + j], |x| x.1))));
        }
        s.push('\n');
    }
    s.push('\n');
    for (j, &l) in limits.iter().enumerate() {
        let worst_ratio = results.iter().flat_map(|r| r.ratios[j].iter().copied()).fold(f64::NEG_INFINITY, f64::max);
        s.push_str(&format!(
            "- towpath at {}: ≤ the best of GA, ACO1 and ACO2 on {}/{total} instances by medians (towpath's median run \
             against the best solver's median run) and on {}/{total} by extremes (towpath's worst run against the \
             best of all their runs); largest median ratio on any instance {worst_ratio:.4}",
            lim(l),
            total_median_wins[j],
            total_wins[j]
        ));
        if let Some(last) = results.last() {
            let aco2 = med(&last.runs[2], |x| x.1);
            let tp = med(&last.runs[3 + j], |x| x.1);
            s.push_str(&format!(
                "; on the largest size its median time is {} ms against ACO2's {} ms ({})",
                ms(tp),
                ms(aco2),
                faster(aco2, tp)
            ));
        }
        s.push_str(".\n");
    }
    s.push_str(
        "\nThe paper's Table I beside ours (its instances are hand-made and unpublished, so only the shape compares; ",
    );
    s.push_str("\"ACO2 vs GA\" is (GA − ACO2) / ACO2, as in the paper):\n\n");
    s.push_str("| data set | paper ACO1 (m) | paper ACO2 (m) | paper GA (m) | paper ACO2 vs GA | ours ACO2 vs GA | paper ACO2 s | ours ACO2 ms |\n");
    s.push_str("|---|---:|---:|---:|---:|---:|---:|---:|\n");
    for (i, r) in results.iter().enumerate() {
        let PaperRow { aco1: a1, aco2: a2, ga, aco2_s: t2 } = PAPER[i];
        s.push_str(&format!(
            "| #{} ({} v, {} re) | {a1:.2} | {a2:.2} | {ga:.2} | {:.1} % | {:.1} % | {} | {} |\n",
            i + 1,
            r.v,
            r.r,
            100.0 * (ga - a2) / a2,
            100.0 * median(&r.aco_vs_ga),
            t2.map_or("< 0.01".to_string(), |t| format!("{t:.2}")),
            ms(med(&r.runs[2], |x| x.1)),
        ));
    }
    s.push('\n');
    s
}
