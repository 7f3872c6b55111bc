//! Searches over recombination sequences: the state with undo, the polder criterion, the
//! greedy / uniform / selective policies, and the exact optimum. Imports `mesh` and the
//! candidate table only.

pub mod optimum;
