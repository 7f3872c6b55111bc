//! Criterion benchmarks of the library's hot paths through its public API, on the built-in
//! meshes: building the candidate table, filling eta with the CPU twin of the GPU kernel,
//! restricting to valid quads, one run of each policy, and the exact optimum.
//!
//! `cargo bench` runs them all (about two minutes); `cargo bench -- sphere` a subset. The
//! `quadrecomb bench ...` commands measure the same code at other sizes and print tables for the
//! README; these give criterion's statistics and its comparison with the previous `cargo bench`.

use criterion::{Criterion, criterion_group, criterion_main};
use quadrecomb::{Algo, CandidateTable, Rule};
use std::hint::black_box;

fn table_and_eta(c: &mut Criterion) {
    for name in ["sphere", "borouchaki"] {
        let mesh = quadrecomb::load(name).expect("built-in mesh");
        c.bench_function(&format!("{name}/candidate table, f64 eta"), |b| {
            b.iter(|| CandidateTable::build(black_box(&mesh)))
        });
        let twin = quadrecomb::internals::gpu::Evaluator::cpu_twin();
        c.bench_function(&format!("{name}/eta, CPU twin of the kernel"), |b| {
            b.iter(|| {
                let mut table = CandidateTable::topology_only(&mesh);
                twin.fill(&mut [(&mesh, &mut table)]).expect("CPU twin");
                table
            })
        });
        let table = CandidateTable::build(&mesh);
        c.bench_function(&format!("{name}/restrict to valid quads"), |b| {
            b.iter(|| table.clone().restrict(&mesh, Rule::default()))
        });
    }
}

fn policies(c: &mut Criterion) {
    let mut group = c.benchmark_group("policies");
    group.sample_size(20);
    for name in ["sphere", "borouchaki"] {
        let mesh = quadrecomb::load(name).expect("built-in mesh");
        let table = CandidateTable::build(&mesh).restrict(&mesh, Rule::default());
        for (label, algo) in [
            ("greedy-nocrit", Algo::greedy_nocrit()),
            ("greedy", Algo::greedy()),
            ("selective h=1", Algo::selective(1)),
            ("selective h=3", Algo::selective(3)),
        ] {
            let mut seed = 0u64;
            group.bench_function(format!("{name}/{label}"), |b| {
                b.iter(|| {
                    seed += 1;
                    quadrecomb::run(&mesh, &table, algo, seed).quality
                })
            });
        }
        group.bench_function(format!("{name}/optimum"), |b| {
            b.iter(|| quadrecomb::optimum(&mesh, &table).quality)
        });
    }
    group.finish();
}

criterion_group!(benches, table_and_eta, policies);
criterion_main!(benches);
