//! quadrecomb: recombine triangle meshes into quad meshes by sequential decision-making.
//!
//! Data flows one way: a mesh file becomes a [`mesh::Mesh`] (geometry and topology), the mesh
//! gives a [`quality::CandidateTable`] (pairs, quad vertices, eta), the table feeds the searches,
//! searches give run records, records give statistics, statistics give reports.

pub mod experiment;
pub mod gpu;
pub mod mesh;
pub mod output;
pub mod quality;
pub mod report;
pub mod search;
pub mod stats;
