//! The parts of the `dhcd` command line that are libraries of their own: the paper's
//! experiment ([`experiment`]: simulate once, replay the frames for every hierarchy method,
//! calibrate the cost model, write the reports) and the mass-spring simulator that drives it
//! ([`sim`]). The kernel library (`dhcd`) knows nothing of either.
#![forbid(unsafe_code)]

pub mod experiment;
pub mod sim;
