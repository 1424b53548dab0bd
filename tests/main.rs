//! One integration-test binary; each module is a suite.

mod capi;
mod cli;
mod hierarchies;
mod io;
mod narrow;
mod scene;
mod self_collision;
mod sim;
