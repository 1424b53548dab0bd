//! What every command that reads mesh files shares: the file size limit (`docs/LIMITS.md`)
//! and the precision the coordinates are read in.

use std::path::Path;

use dhcd::io::{self, Limits};
use dhcd::{AnyHierarchy, Mesh, Precision};

#[derive(clap::Args, Clone, Debug)]
pub struct InputArgs {
    /// Refuse mesh files larger than this many bytes (default: 1 GiB).
    #[arg(long, value_name = "BYTES", default_value_t = io::DEFAULT_MAX_FILE_BYTES)]
    max_file_bytes: u64,
    /// The coordinates' precision: f32, or f64 (PLY doubles and OBJ decimals read at full
    /// precision; every answer exact for the f64 values).
    #[arg(long, value_parser = precision_parser())]
    precision: Option<Precision>,
}

impl InputArgs {
    /// The precision asked for (default f32).
    pub fn precision(&self) -> Precision {
        self.precision.unwrap_or(Precision::F32)
    }

    /// Loads a mesh file within the limit, in the precision asked for.
    pub fn load(&self, path: &Path) -> dhcd::Result<Mesh> {
        io::load_as(
            path,
            &Limits {
                max_file_bytes: self.max_file_bytes,
            },
            self.precision(),
        )
    }

    /// The same limit, f64 always: for the commands that only work in f64 (CCD), which
    /// refuse an explicit `--precision f32`.
    pub fn f64_only(&self, command: &str) -> Result<InputArgs, String> {
        if self.precision == Some(Precision::F32) {
            return Err(format!(
                "{command} reads coordinates in f64 (every answer exact for them); --precision f32 is not available"
            ));
        }
        Ok(InputArgs {
            max_file_bytes: self.max_file_bytes,
            precision: Some(Precision::F64),
        })
    }
}

/// Hands `h` the positions of `mesh` (a pose of its mesh, loaded in the same precision).
pub fn update(h: &mut AnyHierarchy, mesh: &Mesh) -> dhcd::Result<u64> {
    match mesh.positions_f64() {
        Some(p) => h.update_positions_f64(p),
        None => h.update_positions(mesh.positions()),
    }
}

/// Parses `f32` or `f64`, which `--help` lists.
fn precision_parser() -> impl clap::builder::TypedValueParser<Value = Precision> {
    use clap::builder::{PossibleValuesParser, TypedValueParser};
    PossibleValuesParser::new(Precision::ALL.map(Precision::name))
        .try_map(|name| name.parse::<Precision>())
}
