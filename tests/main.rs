//! One integration-test binary; each module is a suite.

mod capi;
#[cfg(feature = "cli")]
mod cli;
#[cfg(feature = "cli")]
mod cli_collide;
mod experiment;
mod hierarchies;
mod io;
mod narrow;
mod scene;
mod self_collision;
mod sim;
mod support;
