//! `dhcd ccd T0 T1 [--method dh|sphere|aabb] [--min-distance D] [--earliest] [--threads N]
//! [--json]`: continuous collision detection over the step from pose T0 to pose T1 of one
//! mesh (the same triangles; every vertex moving on a straight line). Coordinates are read
//! in f64 (PLY doubles and OBJ decimals at full precision) and every answer is exact for
//! them.

use std::io::Write;
use std::path::PathBuf;

use dhcd::error::escaped_path;
use dhcd::io::{self, Limits};
use dhcd::{AnyHierarchy, CcdQuery, Impacts, Mesh, Motion, Par, Precision, Workspace};

use super::query::QueryArgs;

#[derive(clap::Args, Debug)]
pub struct CcdArgs {
    /// The mesh at the start of the step (OBJ, STL or PLY).
    t0: PathBuf,
    /// The same mesh at the end of the step: the same vertices and triangles, new positions.
    t1: PathBuf,
    /// Pairs collide when they come within this distance (IPC's minimum separation).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    min_distance: f64,
    /// Only the earliest time of impact, with every pair whose own time is within 1e-12 of it.
    #[arg(long)]
    earliest: bool,
    /// Threads (1: the calling thread; 0: all cores). The output does not depend on it.
    #[arg(long, default_value_t = 1)]
    threads: usize,
    /// Refuse mesh files larger than this many bytes (default: 1 GiB).
    #[arg(long, value_name = "BYTES", default_value_t = io::DEFAULT_MAX_FILE_BYTES)]
    max_file_bytes: u64,
    #[command(flatten)]
    query: QueryArgs,
}

/// The CCD query of the flags `--min-distance` and `--earliest`, checked.
pub fn ccd_query(min_distance: f64, earliest: bool) -> dhcd::Result<CcdQuery> {
    let q = if earliest {
        CcdQuery::earliest()
    } else {
        CcdQuery::all()
    }
    .with_min_distance(min_distance);
    q.options.validate()?;
    Ok(q)
}

/// Loads the two poses of a step in f64; the second must have the first's triangles.
pub fn load_step(t0: &PathBuf, t1: &PathBuf, max_file_bytes: u64) -> Result<[Mesh; 2], String> {
    let limits = Limits { max_file_bytes };
    let load = |p: &PathBuf| io::load_as(p, &limits, Precision::F64).map_err(|e| e.to_string());
    let (m0, m1) = (load(t0)?, load(t1)?);
    if m0.vertex_count() != m1.vertex_count() || m0.triangles() != m1.triangles() {
        return Err(format!(
            "{}: not a pose of {} (the end of a step must have the start's vertices and triangles)",
            escaped_path(t1),
            escaped_path(t0)
        ));
    }
    Ok([m0, m1])
}

/// The f64 positions of a mesh loaded in f64.
pub fn f64_positions(m: &Mesh) -> &[[f64; 3]] {
    m.positions_f64().expect("loaded in f64")
}

pub fn run(args: CcdArgs) -> Result<(), String> {
    let q = &args.query;
    let par = Par::threads(args.threads).map_err(|e| e.to_string())?;
    // Options are checked before any file is read.
    let query = ccd_query(args.min_distance, args.earliest).map_err(|e| e.to_string())?;
    let [m0, m1] = load_step(&args.t0, &args.t1, args.max_file_bytes)?;
    let h = AnyHierarchy::new(q.method, &m0, q.options()).map_err(|e| e.to_string())?;
    let motion = Motion::new(f64_positions(&m0), f64_positions(&m1));
    let impacts = h
        .self_ccd(motion, &query, &mut Workspace::default(), par)
        .map_err(|e| e.to_string())?;
    super::emit_with(|out| {
        if q.json {
            write_json(out, &args, &impacts)
        } else {
            write_text(out, &args, &impacts)
        }
    })
    .map_err(|e| e.to_string())
}

/// `{"method", "precision", "min_distance", "earliest", "toi", "vertex_face": [[v, t, toi],
/// ...], "edge_edge": [[a0, a1, b0, b1, toi], ...], "counters"}`, streamed; `toi` is null
/// when nothing collides.
fn write_json(out: &mut dyn Write, args: &CcdArgs, p: &Impacts) -> std::io::Result<()> {
    let num = |x: f64| serde_json::Number::from_f64(x).map_or("null".into(), |n| n.to_string());
    write!(
        out,
        "{{\"method\":\"{}\",\"precision\":\"f64\",\"min_distance\":{},\"earliest\":{},\"toi\":{},\"vertex_face\":[",
        args.query.method.name(),
        num(args.min_distance),
        args.earliest,
        p.toi.map_or("null".into(), num),
    )?;
    for (k, x) in p.vertex_face.iter().enumerate() {
        let sep = if k == 0 { "" } else { "," };
        write!(out, "{sep}[{},{},{}]", x.vertex, x.triangle, num(x.toi))?;
    }
    out.write_all(b"],\"edge_edge\":[")?;
    for (k, x) in p.edge_edge.iter().enumerate() {
        let sep = if k == 0 { "" } else { "," };
        write!(
            out,
            "{sep}[{},{},{},{},{}]",
            x.a[0],
            x.a[1],
            x.b[0],
            x.b[1],
            num(x.toi)
        )?;
    }
    let c = p.counters;
    writeln!(
        out,
        "],\"counters\":{{\"bv_tests\":{},\"prim_tests\":{},\"bv_updates\":{},\"contacts\":{}}}}}",
        c.bv_tests, c.prim_tests, c.bv_updates, c.contacts
    )
}

/// A summary line, then one line per pair: `vf VERTEX TRIANGLE TOI`, `ee A0 A1 B0 B1 TOI`.
fn write_text(out: &mut dyn Write, args: &CcdArgs, p: &Impacts) -> std::io::Result<()> {
    let c = p.counters;
    let toi = p.toi.map_or("none".to_string(), |t| format!("{t:e}"));
    writeln!(
        out,
        "{} vertex-face and {} edge-edge pairs collide{} (earliest time of impact {toi}; {}, \
         min distance {:?}): {} BV pairs tested, {} feature pairs tested, {} BV updates",
        p.vertex_face.len(),
        p.edge_edge.len(),
        if args.earliest {
            " at the earliest time"
        } else {
            ""
        },
        args.query.method,
        args.min_distance,
        c.bv_tests,
        c.prim_tests,
        c.bv_updates
    )?;
    for x in &p.vertex_face {
        writeln!(out, "vf {} {} {:e}", x.vertex, x.triangle, x.toi)?;
    }
    for x in &p.edge_edge {
        let (a, b) = (x.a, x.b);
        writeln!(out, "ee {} {} {} {} {:e}", a[0], a[1], b[0], b[1], x.toi)?;
    }
    Ok(())
}
