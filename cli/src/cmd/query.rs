//! What `collide`, `self` and `scene` share: the hierarchy flags and the contact report
//! (one JSON object with `--json`, otherwise a summary line and one contact per line).

use std::io::Write;

use dhcd::{CentralVertex, Counters, Method, Options, Precision};

#[derive(clap::Args, Debug)]
pub struct QueryArgs {
    /// Bounding-volume hierarchy.
    #[arg(long, default_value_t = Method::Dh, value_parser = super::method_parser(), ignore_case = true)]
    pub method: Method,
    /// A fixed depth for the region tree (root = level 0; the paper uses 5). Default: an
    /// adaptive tree.
    #[arg(long)]
    pub levels: Option<usize>,
    /// Largest number of triangles per leaf of the adaptive tree.
    #[arg(long, default_value_t = dhcd::tree::DEFAULT_LEAF_SIZE)]
    pub leaf_size: usize,
    /// The DH central vertex of each region: the paper's (closest to the rest centroid) or
    /// the one of least rest radius (tighter, slower to build). Other methods ignore it.
    #[arg(long, default_value_t = CentralVertex::RestCentroid, value_parser = super::central_parser())]
    pub central: CentralVertex,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

impl QueryArgs {
    pub fn options(&self) -> Options {
        Options {
            levels: self.levels,
            leaf_size: self.leaf_size,
            central: self.central,
            ..Options::default()
        }
    }

    /// Prints the contacts (`rows`, each a contact's indices) and counters. `what` names
    /// the contacts in the text summary, e.g. "contacts" or "self-contacts".
    /// `levels` is the depth of the built trees (the deepest, for several objects).
    ///
    /// The report is streamed row by row: a query with millions of contacts needs no memory
    /// beyond the library's own contact array.
    pub fn report<const N: usize, T: Copy + Into<u64>>(
        &self,
        what: &str,
        precision: Precision,
        levels: usize,
        rows: &[[T; N]],
        counters: Counters,
    ) -> dhcd::Result<()> {
        super::emit_with(|out| {
            if self.json {
                self.write_json(out, precision, levels, rows, counters)
            } else {
                self.write_text(out, what, levels, rows, counters)
            }
        })
    }

    /// A summary line, then one line per contact.
    fn write_text<const N: usize, T: Copy + Into<u64>>(
        &self,
        out: &mut dyn Write,
        what: &str,
        levels: usize,
        rows: &[[T; N]],
        counters: Counters,
    ) -> std::io::Result<()> {
        writeln!(
            out,
            "{} {what} ({} levels, {} bytes per node): {} BV pairs tested, {} triangle pairs tested, {} BV updates",
            rows.len(),
            levels,
            self.method.bytes_per_node(),
            counters.bv_tests,
            counters.prim_tests,
            counters.bv_updates
        )?;
        for row in rows {
            for (i, &x) in row.iter().enumerate() {
                let x: u64 = x.into();
                if i == 0 {
                    write!(out, "{x}")?;
                } else {
                    write!(out, " {x}")?;
                }
            }
            writeln!(out)?;
        }
        Ok(())
    }

    /// One compact JSON object and a newline: `{"method", "precision", "levels",
    /// "bytes_per_node", "pairs", "counters"}`, keys in this order, the bytes `serde_json`
    /// prints for it.
    fn write_json<const N: usize, T: Copy + Into<u64>>(
        &self,
        out: &mut dyn Write,
        precision: Precision,
        levels: usize,
        rows: &[[T; N]],
        counters: Counters,
    ) -> std::io::Result<()> {
        out.write_all(b"{\"method\":")?;
        serde_json::to_writer(&mut *out, self.method.name())?;
        write!(out, ",\"precision\":\"{}\"", precision.name())?;
        write!(
            out,
            ",\"levels\":{levels},\"bytes_per_node\":{},\"pairs\":[",
            self.method.bytes_per_node()
        )?;
        for (k, row) in rows.iter().enumerate() {
            out.write_all(if k == 0 { b"[" } else { b",[" })?;
            for (i, &x) in row.iter().enumerate() {
                let x: u64 = x.into();
                if i == 0 {
                    write!(out, "{x}")?;
                } else {
                    write!(out, ",{x}")?;
                }
            }
            out.write_all(b"]")?;
        }
        writeln!(
            out,
            "],\"counters\":{{\"bv_tests\":{},\"prim_tests\":{},\"bv_updates\":{},\"contacts\":{}}}}}",
            counters.bv_tests, counters.prim_tests, counters.bv_updates, counters.contacts
        )
    }
}
