//! Statistics: plain numbers in, numbers out.

pub mod compare;
pub mod describe;
pub mod dist;
pub mod ranks;
