//! One integration-test binary; each module is a suite.

#[cfg(feature = "cli")]
mod cli_collide;
mod hierarchies;
mod io;
mod narrow;
mod sim;
