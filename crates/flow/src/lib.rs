//! porofrac-flow (under construction).
