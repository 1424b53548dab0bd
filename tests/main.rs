//! One integration-test binary; each module is a suite.

mod experiment;
mod hierarchies;
mod io;
mod narrow;
mod sim;
