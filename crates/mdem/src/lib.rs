//! porofrac-mdem (under construction).
