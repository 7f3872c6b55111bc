//! `quadrecomb bench memory`: this machine's random-access latency by working-set size.
//!
//! The search's time per triangle on a large mesh rests on it: each decision starts at a
//! random place on the front and follows chains of dependent loads (triangle, candidate,
//! vertex) there (docs/search.md, "Where the time goes"). Two figures per size, over a
//! buffer of `u64`s:
//! * dependent: a pointer chase around one random cycle (Sattolo's shuffle), so each load's
//!   address comes from the load before it, as in the search's chains;
//! * independent: addresses from a generator that reads no memory, so the core overlaps
//!   the misses (what prefetching or batching could at best reach).

use crate::cli::UsageError;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;
use std::process::ExitCode;
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Largest working set in MiB; sizes double from 1 MiB up to it.
    #[arg(long, default_value_t = 512)]
    max_mib: usize,
    /// Loads timed per size and kind.
    #[arg(long, default_value_t = 2_000_000)]
    loads: usize,
}

/// One random cycle through `0..n` as a successor table (Sattolo's algorithm); `None` when
/// the memory cannot be had.
fn random_cycle(n: usize, rng: &mut ChaCha8Rng) -> Option<Vec<u64>> {
    let mut order: Vec<u64> = Vec::new();
    crate::cli::oom::fallible(|| order.try_reserve_exact(n)).ok()?;
    order.extend(0..n as u64);
    for i in (1..n).rev() {
        let j = rng.random_range(0..i);
        order.swap(i, j);
    }
    // Sattolo's shuffle leaves a single n-cycle: `order` read as a successor table.
    Some(order)
}

/// Nanoseconds per load of a chase of `loads` steps around `next`.
fn dependent_ns(next: &[u64], loads: usize) -> f64 {
    let start = Instant::now();
    let mut p = 0usize;
    for _ in 0..loads {
        p = next[p] as usize;
    }
    black_box(p);
    start.elapsed().as_secs_f64() * 1e9 / loads as f64
}

/// Nanoseconds per load of `loads` loads at xorshift-generated positions in `data`.
fn independent_ns(data: &[u64], loads: usize) -> f64 {
    let n = data.len() as u64;
    let start = Instant::now();
    let (mut x, mut acc) = (0x9E37_79B9_7F4A_7C15u64, 0u64);
    for _ in 0..loads {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        acc = acc.wrapping_add(data[(x % n) as usize]);
    }
    black_box(acc);
    start.elapsed().as_secs_f64() * 1e9 / loads as f64
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    if args.max_mib == 0 {
        return Err(UsageError("--max-mib must be at least 1".into()).into());
    }
    if args.loads == 0 {
        return Err(UsageError("--loads must be at least 1".into()).into());
    }
    outln!(
        "random loads of 8 bytes, {} per size and kind (ns per load; lower is faster)",
        args.loads
    );
    outln!(
        "{:>8} {:>14} {:>16} {:>8}",
        "MiB",
        "dependent ns",
        "independent ns",
        "ratio"
    );
    let mut rng = ChaCha8Rng::seed_from_u64(2026);
    let mut mib = 1;
    while mib <= args.max_mib {
        let Some(next) = mib
            .checked_mul(1 << 17)
            .and_then(|n| random_cycle(n, &mut rng))
        else {
            return Err(UsageError(format!(
                "cannot allocate {mib} MiB for the working set: lower --max-mib"
            ))
            .into());
        };
        // A first pass faults the pages in and warms what fits in the caches.
        dependent_ns(&next, next.len().min(args.loads));
        let dep = dependent_ns(&next, args.loads);
        let ind = independent_ns(&next, args.loads);
        outln!("{mib:>8} {dep:>14.1} {ind:>16.1} {:>8.1}", dep / ind);
        let Some(twice) = mib.checked_mul(2) else {
            break;
        };
        mib = twice;
    }
    Ok(ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_chase_visits_every_slot_once_per_cycle() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        for n in [2, 3, 10, 1000] {
            let next = random_cycle(n, &mut rng).expect("a few KiB");
            let mut seen = vec![false; n];
            let mut p = 0usize;
            for _ in 0..n {
                assert!(!seen[p], "slot {p} visited twice in a cycle of {n}");
                seen[p] = true;
                p = next[p] as usize;
            }
            assert_eq!(p, 0, "the chase returns to its start after {n} steps");
        }
    }
}
