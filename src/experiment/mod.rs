//! Experiments: seeded, parallel, resumable horizon sweeps and their run records.
