//! One integration-test binary for the command line, the experiment and the simulator; each
//! module is a suite.

mod bench;
mod cli;
mod cli_ccd;
mod cli_collide;
mod cli_proximity;
mod experiment;
// The mesh fixtures, the mutation fuzzer and the temporary directories are the library's
// (one copy of each).
#[path = "../../tests/fixtures.rs"]
mod fixtures;
mod fuzz;
mod hostile;
#[path = "../../tests/mutation.rs"]
mod mutation;
mod sim;
mod support;
#[path = "../../tests/temp_dir.rs"]
mod temp_dir;
