//! Procedural meshes of any size, without Gmsh: jittered right-triangle grids and icospheres.
