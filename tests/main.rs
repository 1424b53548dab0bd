//! One integration-test binary; each module is a suite. (The CLI, experiment and simulator
//! suites live in `cli/tests/`, the C ABI's in `capi/tests/`.)

mod ccd_cases;
mod ccd_frames;
mod ccd_query;
mod ccd_reference;
mod ccd_samples;
mod ccd_wide;
mod central;
mod clearance;
mod contact_set;
mod control;
mod distance;
mod fixtures;
mod free_points;
mod fuzz;
mod hierarchies;
mod io;
mod memory;
mod methods;
mod mutation;
mod narrow;
mod precision;
mod proximity;
mod real_frames;
mod scene;
mod scene_ccd;
mod self_collision;
mod shared_pairs;
mod step_size;
mod support;
mod temp_dir;
mod threads;
mod tree;
