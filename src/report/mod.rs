//! Reports: tables, box plots, mesh pictures and statistical comparisons from sweep results.
