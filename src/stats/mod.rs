//! Statistics: plain numbers in, numbers out.

pub mod compare;
pub mod describe;
