//! Comparisons of samples: Mann–Whitney U with Holm correction, Vargha–Delaney A, bootstrap CIs.
