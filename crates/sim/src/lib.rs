//! porofrac-sim (under construction).
