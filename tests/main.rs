//! One integration-test binary; each module is a suite.

mod hierarchies;
mod io;
mod narrow;
mod sim;
