//! porofrac-vem (under construction).
