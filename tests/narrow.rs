//! Tests of `dhcd::narrow` (suite being written).
