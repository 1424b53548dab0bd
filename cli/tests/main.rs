//! One integration-test binary for the command line, the experiment and the simulator; each
//! module is a suite.

mod cli;
mod cli_collide;
mod experiment;
mod sim;
mod support;
