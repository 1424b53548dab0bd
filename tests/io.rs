//! Tests of `dhcd::io` (suite being written).
