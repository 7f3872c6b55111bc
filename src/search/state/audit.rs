//! An audit hook on the look-ahead tree, for tests: a function called after every
//! [`State::tree_push`] and [`State::tree_pop`] with a view of the node reached (the base
//! actions, the tree's path, the remaining triangles and the tree's verdicts), so that a test
//! can compare the verdicts the policies rely on with an oracle while the policies run.
//! Unset (the default), it costs one never-taken branch per push and pop.

use super::State;
use crate::mesh::Mesh;
use crate::quality::CandidateTable;

/// What the tree just did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TreeEvent {
    /// `tree_push(c)`.
    Push(u32),
    /// `tree_pop()`, which reverted the push of this candidate.
    Pop(u32),
}

/// The hook: a plain function (no captured state; a test keeps its own in a thread local).
pub type TreeAudit = fn(&mut TreeView<'_, '_>, TreeEvent);

/// The node of the look-ahead tree after a push or pop, as the hook sees it: queries only
/// (the tree's queries take `&mut` for their caches, which change no verdict).
#[derive(Debug)]
pub struct TreeView<'s, 'a>(&'s mut State<'a>);

impl<'a> TreeView<'_, 'a> {
    /// The mesh.
    pub fn mesh(&self) -> &'a Mesh {
        self.0.mesh
    }

    /// The candidate table.
    pub fn table(&self) -> &'a CandidateTable {
        self.0.table
    }

    /// The actions applied before the tree began (the decisions so far), in order.
    pub fn base(&self) -> &[u32] {
        &self.0.chosen
    }

    /// The tree's path from its root to this node.
    pub fn path(&self) -> &[u32] {
        &self.0.tree.path
    }

    /// True when triangle `t` remains at this node.
    pub fn is_remaining(&self, t: u32) -> bool {
        self.0.alive[t as usize]
    }

    /// [`State::tree_allowed`] at this node.
    pub fn tree_allowed(&mut self, c: u32) -> bool {
        self.0.tree_allowed(c)
    }

    /// [`State::tree_count`] at this node.
    pub fn tree_count(&mut self, t: u32) -> u32 {
        self.0.tree_count(t)
    }
}

impl State<'_> {
    /// Sets (or, with `None`, removes) the hook called after every tree push and pop.
    pub fn set_tree_audit(&mut self, audit: Option<TreeAudit>) {
        self.audit = audit;
    }

    /// Calls the hook, if set.
    #[inline(always)]
    pub(super) fn audit_tree(&mut self, event: TreeEvent) {
        if let Some(f) = self.audit {
            self.call_audit(f, event);
        }
    }

    #[cold]
    #[inline(never)]
    fn call_audit(&mut self, f: TreeAudit, event: TreeEvent) {
        f(&mut TreeView(self), event);
    }
}
