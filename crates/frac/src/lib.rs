//! porofrac-frac (under construction).
