//! Tests of `dhcd::sim` (suite being written).
