//! One integration-test binary for the command line, the experiment and the simulator; each
//! module is a suite.

mod bench;
mod cli;
mod cli_collide;
mod experiment;
// The mesh fixtures and the mutation fuzzer are the library's (one copy of each).
#[path = "../../tests/fixtures.rs"]
mod fixtures;
mod fuzz;
mod hostile;
#[path = "../../tests/mutation.rs"]
mod mutation;
mod sim;
mod support;
