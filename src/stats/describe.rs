//! Descriptive statistics: quantiles, box-plot figures, mean and deviation, growth fits.
