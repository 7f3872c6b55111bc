//! Fuzz target: the MSH readers (every version and type) must never panic, and every mesh
//! they accept must pass `sanity_check`, give a candidate table, and survive a write/read.
#![no_main]

use libfuzzer_sys::fuzz_target;
use quadrecomb::internals::mesh::{Recombined, msh};
use quadrecomb::internals::quality::CandidateTable;

fuzz_target!(|data: &[u8]| {
    if let Ok(m) = msh::read_bytes("fuzz.msh", data) {
        m.sanity_check().expect("an accepted mesh is sane");
        let table = CandidateTable::build(&m);
        assert!(table.eta.iter().all(|e| (0.0..=1.0).contains(e)));
        let mut out = Vec::new();
        msh::write_to(&mut out, &m, &Recombined::unrecombined(&m)).expect("write");
        let back = msh::read_bytes("written.msh", &out).expect("written mesh reads back");
        assert_eq!(back.num_triangles(), m.num_triangles());
    }
});
