//! What every command that reads mesh files shares: the file size limit (`docs/LIMITS.md`).

use std::path::Path;

use dhcd::io::{self, Limits};
use dhcd::Mesh;

#[derive(clap::Args, Debug)]
pub struct InputArgs {
    /// Refuse mesh files larger than this many bytes (default: 1 GiB).
    #[arg(long, value_name = "BYTES", default_value_t = io::DEFAULT_MAX_FILE_BYTES)]
    max_file_bytes: u64,
}

impl InputArgs {
    /// Loads a mesh file within the limit.
    pub fn load(&self, path: &Path) -> dhcd::Result<Mesh> {
        io::load_with(
            path,
            &Limits {
                max_file_bytes: self.max_file_bytes,
            },
        )
    }
}
