//! What `collide`, `self` and `scene` share: the hierarchy flags and the contact report
//! (one JSON object with `--json`, otherwise a summary line and one contact per line).

use dhcd::{Counters, Method, Options};
use serde_json::json;

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
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

impl QueryArgs {
    pub fn options(&self) -> Options {
        Options {
            levels: self.levels,
            leaf_size: self.leaf_size,
            ..Options::default()
        }
    }

    /// Prints the contacts (`rows`, each a contact's indices) and counters. `what` names
    /// the contacts in the text summary, e.g. "contacts" or "self-contacts".
    /// `levels` is the depth of the built trees (the deepest, for several objects).
    pub fn report<const N: usize, T: Copy + Into<u64>>(
        &self,
        what: &str,
        levels: usize,
        rows: &[[T; N]],
        counters: Counters,
    ) -> dhcd::Result<()> {
        use std::fmt::Write;
        let rows: Vec<[u64; N]> = rows.iter().map(|r| r.map(Into::into)).collect();
        if self.json {
            return super::emit(&format!("{}\n", self.json_value(levels, &rows, counters)));
        }
        let mut text = String::new();
        let _ = writeln!(
            text,
            "{} {what} ({} levels, {} bytes per node): {} BV pairs tested, {} triangle pairs tested, {} BV updates",
            rows.len(),
            levels,
            self.method.bytes_per_node(),
            counters.bv_tests,
            counters.prim_tests,
            counters.bv_updates
        );
        for row in &rows {
            let line: Vec<String> = row.iter().map(u64::to_string).collect();
            let _ = writeln!(text, "{}", line.join(" "));
        }
        super::emit(&text)
    }

    /// `{"method", "levels", "bytes_per_node", "pairs", "counters"}`, keys in this order.
    fn json_value<const N: usize>(
        &self,
        levels: usize,
        rows: &[[u64; N]],
        counters: Counters,
    ) -> serde_json::Value {
        json!({
            "method": self.method.name(),
            "levels": levels,
            "bytes_per_node": self.method.bytes_per_node(),
            "pairs": rows.iter().map(|r| r.to_vec()).collect::<Vec<_>>(),
            "counters": {
                "bv_tests": counters.bv_tests,
                "prim_tests": counters.prim_tests,
                "bv_updates": counters.bv_updates,
                "contacts": counters.contacts,
            },
        })
    }
}
