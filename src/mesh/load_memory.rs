//! Test of the load's memory: the lib's test binary counts, per thread, the bytes its
//! allocator has live, so that a test can measure the heap its own thread's work peaked at
//! (tests run on parallel threads; loading uses one).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

/// The system allocator, with each thread's live bytes and their peak counted.
struct Counting;

thread_local! {
    /// (live bytes, peak live bytes) allocated by this thread (less what it freed).
    static LIVE: Cell<(isize, isize)> = const { Cell::new((0, 0)) };
}

fn add(bytes: isize) {
    // `try_with`: nothing is counted while the thread's locals are being destroyed.
    let _ = LIVE.try_with(|c| {
        let (live, peak) = c.get();
        let live = live + bytes;
        c.set((live, peak.max(live)));
    });
}

// SAFETY: every call is forwarded to `System` with the same arguments; the counting touches
// a const-initialised thread local, which does not allocate.
#[allow(unsafe_code)]
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: forwarded as is.
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            add(layout.size() as isize);
        }
        p
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: forwarded as is.
        let p = unsafe { System.alloc_zeroed(layout) };
        if !p.is_null() {
            add(layout.size() as isize);
        }
        p
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded as is.
        unsafe { System.dealloc(ptr, layout) };
        add(-(layout.size() as isize));
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: forwarded as is.
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            add(new_size as isize - layout.size() as isize);
        }
        p
    }
}

#[global_allocator]
static COUNTING: Counting = Counting;

/// Runs `f` and returns its result, the bytes it left allocated and the peak of its
/// allocations above what was live when it started, both on this thread.
fn measured<T>(f: impl FnOnce() -> T) -> (T, isize, isize) {
    let (live0, _) = LIVE.with(Cell::get);
    LIVE.with(|c| c.set((live0, live0)));
    let out = f();
    let (live, peak) = LIVE.with(Cell::get);
    (out, live - live0, peak - live0)
}

/// Loading a one-cell strip (one vertex per triangle, the most per triangle of the
/// generated shapes) peaks at most 130 bytes per triangle (120 measured: the file's bytes and the parsed arrays, at the
/// parse's end), and the mesh it gives takes at
/// most 90. Before #26's load work: 290 and 125 (the file's bytes alive, at twice the
/// file's size, while the mesh was built; the topology's 16-byte half-edge tuples and their
/// sort; the edges kept in the mesh).
#[test]
fn loading_a_strip_peaks_under_130_bytes_per_triangle() {
    use crate::mesh::generate::{Corridor, corridor};
    let n = 100_000;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("strip.msh");
    let strip = corridor(Corridor::Strip, n, 0);
    crate::mesh::msh::write(
        &path,
        &strip,
        &crate::mesh::Recombined::unrecombined(&strip),
    )
    .unwrap();
    drop(strip);
    let spec = path.to_str().unwrap();
    let (mesh, left, peak) = measured(|| crate::mesh::load(spec).unwrap());
    assert_eq!(mesh.num_triangles(), n);
    let (left, peak) = (left as f64 / n as f64, peak as f64 / n as f64);
    assert!(peak <= 130.0, "peak {peak:.1} bytes per triangle");
    assert!(left <= 90.0, "mesh {left:.1} bytes per triangle");
}
