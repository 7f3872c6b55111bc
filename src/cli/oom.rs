//! Out of memory: a failed allocation ends the process with exit code 5 and a message that
//! says what was being done and how much could not be had (Rust's default is to abort:
//! exit 134, "memory allocation of N bytes failed"). The command line names its phases
//! ([`phase`]); the library knows nothing of this. Code that asks for memory it can do
//! without (`try_reserve`) runs inside [`fallible`] and gets its error back.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::fmt::Write;
use std::sync::atomic::{AtomicU8, AtomicUsize, Ordering};

/// What the command was doing, named in the message.
#[derive(Debug, Clone, Copy)]
#[repr(u8)]
pub enum Phase {
    Start,
    Reading,
    Mesh,
    Candidates,
    Search,
    Optimum,
    Writing,
    Sweep,
    Replay,
    Report,
    Merge,
    Generate,
}

impl Phase {
    fn describe(self) -> &'static str {
        match self {
            Phase::Start => "starting",
            Phase::Reading => "reading the mesh file",
            Phase::Mesh => "building the mesh (elements, topology, components)",
            Phase::Candidates => "building the candidate table",
            Phase::Search => "searching (the state's verdicts and trees)",
            Phase::Optimum => "computing the optimum",
            Phase::Writing => "writing the output",
            Phase::Sweep => "running the sweep (its meshes, their optimum, the runs, the report)",
            Phase::Replay => "replaying the run (its mesh, the search, the export)",
            Phase::Report => "making the report (the records, statistics and figures)",
            Phase::Merge => "merging the sweeps (their records)",
            Phase::Generate => "generating the mesh",
        }
    }

    fn from_u8(v: u8) -> Phase {
        [
            Phase::Start,
            Phase::Reading,
            Phase::Mesh,
            Phase::Candidates,
            Phase::Search,
            Phase::Optimum,
            Phase::Writing,
            Phase::Sweep,
            Phase::Replay,
            Phase::Report,
            Phase::Merge,
            Phase::Generate,
        ]
        .get(v as usize)
        .copied()
        .unwrap_or(Phase::Start)
    }
}

static PHASE: AtomicU8 = AtomicU8::new(0);
/// Triangles of the mesh being worked on (0 before it is read).
static TRIANGLES: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    /// Inside [`fallible`]: a failed allocation is returned to its caller.
    static FALLIBLE: Cell<bool> = const { Cell::new(false) };
}

/// Names what the command does from now on.
pub fn phase(p: Phase) {
    PHASE.store(p as u8, Ordering::Relaxed);
}

/// Records the mesh's size for the message.
pub fn mesh_size(triangles: usize) {
    TRIANGLES.store(triangles, Ordering::Relaxed);
}

/// Runs `f` with failed allocations returned to it (`try_reserve` errors) instead of ending
/// the process.
pub fn fallible<R>(f: impl FnOnce() -> R) -> R {
    let was = FALLIBLE.with(|c| c.replace(true));
    let r = f();
    FALLIBLE.with(|c| c.set(was));
    r
}

/// The system allocator, ending the process with a message when it fails.
#[derive(Debug)]
pub struct ExitOnOom;

/// A message written without allocating (on the stack).
struct Message {
    buf: [u8; 512],
    len: usize,
}

impl Write for Message {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        let n = s.len().min(self.buf.len() - self.len);
        self.buf[self.len..self.len + n].copy_from_slice(&s.as_bytes()[..n]);
        self.len += n;
        Ok(())
    }
}

/// An allocation of `size` bytes failed: unless the caller asked to see it, say so and
/// exit with code 5 (out of memory: the input is too large for the memory this process may
/// have).
fn failed(size: usize) {
    if FALLIBLE.try_with(Cell::get).unwrap_or(false) {
        return;
    }
    let mut m = Message {
        buf: [0; 512],
        len: 0,
    };
    let phase = Phase::from_u8(PHASE.load(Ordering::Relaxed)).describe();
    let _ = write!(
        m,
        "error: out of memory while {phase}: could not allocate {:.1} MiB ({size} bytes)",
        size as f64 / (1u64 << 20) as f64
    );
    let nt = TRIANGLES.load(Ordering::Relaxed);
    if nt > 0 {
        let _ = write!(m, " for a mesh of {nt} triangles");
    }
    let _ = writeln!(
        m,
        "; give the process more memory (ulimit -v, container limits) or use a smaller mesh"
    );
    exit_with(&m.buf[..m.len]);
}

/// Writes `msg` to stderr and ends the process with code 5 (`EXIT_OUT_OF_MEMORY`), allocating
/// nothing and running no destructor (the heap may be in use by the failed call).
#[allow(unsafe_code)]
fn exit_with(msg: &[u8]) -> ! {
    // SAFETY: write(2) reads `msg` for its length; _exit ends the process at once.
    unsafe {
        libc::write(2, msg.as_ptr().cast(), msg.len());
        libc::_exit(i32::from(super::errors::EXIT_OUT_OF_MEMORY))
    }
}

#[allow(unsafe_code)]
// SAFETY: every method forwards to the system allocator with the same arguments and returns
// what it returned; on failure `failed` either returns (null goes back to the caller, as
// from System) or ends the process.
unsafe impl GlobalAlloc for ExitOnOom {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if p.is_null() {
            failed(layout.size());
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc_zeroed(layout) };
        if p.is_null() {
            failed(layout.size());
        }
        p
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if p.is_null() {
            failed(new_size);
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}
