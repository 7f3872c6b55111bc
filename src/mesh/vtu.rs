//! VTK `.vtu` (XML unstructured grid) writer for ParaView, with per-cell quality.
