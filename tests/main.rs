//! One integration-test binary; each module is a suite.

mod io;
mod narrow;
mod sim;
