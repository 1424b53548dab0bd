//! `dhcd proximity MESH [OTHER] --distance D [--method dh|sphere|aabb] [--precision f32|f64]
//! [--threads N] [--json]`: every vertex-triangle and edge-edge pair within the distance, of
//! one mesh (self-proximity) or between two.

use std::io::Write;
use std::path::PathBuf;

use dhcd::{AnyHierarchy, Par, Proximity, Workspace};

use super::input::InputArgs;
use super::query::QueryArgs;

#[derive(clap::Args, Debug)]
pub struct ProximityArgs {
    /// The mesh (OBJ, STL or PLY).
    mesh: PathBuf,
    /// A second mesh: pairs between the two instead of inside MESH.
    other: Option<PathBuf>,
    /// The distance: a pair is reported when its closed features are at most this far apart.
    #[arg(long, allow_hyphen_values = true)]
    distance: f64,
    /// Threads (1: the calling thread; 0: all cores). The output does not depend on it.
    #[arg(long, default_value_t = 1)]
    threads: usize,
    #[command(flatten)]
    query: QueryArgs,
    #[command(flatten)]
    input: InputArgs,
}

pub fn run(args: ProximityArgs) -> dhcd::Result<()> {
    let q = &args.query;
    let par = Par::threads(args.threads)?;
    // The distance is checked before any file is read.
    if !(args.distance.is_finite() && args.distance >= 0.0) {
        return Err(dhcd::Error::InvalidDistance(args.distance));
    }
    let mesh = args.input.load(&args.mesh)?;
    let h = AnyHierarchy::new(q.method, &mesh, q.options())?;
    let mut ws = Workspace::default();
    let p = match &args.other {
        None => h.self_proximity(args.distance, &mut ws, par)?,
        Some(path) => {
            let other = args.input.load(path)?;
            let o = AnyHierarchy::new(q.method, &other, q.options())?;
            h.proximity(&o, args.distance, &mut ws, par)?
        }
    };
    super::emit_with(|out| {
        if q.json {
            write_json(out, &args, &p)
        } else {
            write_text(out, &args, &p)
        }
    })
}

/// `{"method", "precision", "distance", "vertex_face": [[v, t, dist_sq, type], ...],
/// ("face_vertex": [[t, v, dist_sq, type], ...],) "edge_edge": [[a0, a1, b0, b1, dist_sq,
/// type], ...], "counters"}`, streamed (`face_vertex` with two meshes); `type` is IPC's
/// distance type name, as in the text output.
fn write_json(out: &mut dyn Write, args: &ProximityArgs, p: &Proximity) -> std::io::Result<()> {
    let num = |x: f64| serde_json::Number::from_f64(x).map_or("null".into(), |n| n.to_string());
    write!(
        out,
        "{{\"method\":\"{}\",\"precision\":\"{}\",\"distance\":{},\"vertex_face\":[",
        args.query.method.name(),
        args.input.precision().name(),
        num(args.distance)
    )?;
    for (k, x) in p.vertex_face.iter().enumerate() {
        let sep = if k == 0 { "" } else { "," };
        write!(
            out,
            "{sep}[{},{},{},\"{}\"]",
            x.vertex,
            x.triangle,
            num(x.distance_sq),
            x.kind.ipc_name()
        )?;
    }
    if args.other.is_some() {
        out.write_all(b"],\"face_vertex\":[")?;
        for (k, x) in p.face_vertex.iter().enumerate() {
            let sep = if k == 0 { "" } else { "," };
            write!(
                out,
                "{sep}[{},{},{},\"{}\"]",
                x.triangle,
                x.vertex,
                num(x.distance_sq),
                x.kind.ipc_name()
            )?;
        }
    }
    out.write_all(b"],\"edge_edge\":[")?;
    for (k, x) in p.edge_edge.iter().enumerate() {
        let sep = if k == 0 { "" } else { "," };
        write!(
            out,
            "{sep}[{},{},{},{},{},\"{}\"]",
            x.a[0],
            x.a[1],
            x.b[0],
            x.b[1],
            num(x.distance_sq),
            x.kind.ipc_name()
        )?;
    }
    let c = p.counters;
    writeln!(
        out,
        "],\"counters\":{{\"bv_tests\":{},\"prim_tests\":{},\"bv_updates\":{},\"contacts\":{}}}}}",
        c.bv_tests, c.prim_tests, c.bv_updates, c.contacts
    )
}

/// A summary line, then one line per pair: `vf VERTEX TRIANGLE DIST_SQ TYPE`, `fv TRIANGLE
/// VERTEX DIST_SQ TYPE`, `ee A0 A1 B0 B1 DIST_SQ TYPE` (IPC's type names).
fn write_text(out: &mut dyn Write, args: &ProximityArgs, p: &Proximity) -> std::io::Result<()> {
    let c = p.counters;
    writeln!(
        out,
        "{} vertex-face, {} face-vertex and {} edge-edge pairs within {:?} ({}, {}): {} BV pairs \
         tested, {} feature pairs tested, {} BV updates",
        p.vertex_face.len(),
        p.face_vertex.len(),
        p.edge_edge.len(),
        args.distance,
        args.query.method,
        args.input.precision(),
        c.bv_tests,
        c.prim_tests,
        c.bv_updates
    )?;
    for x in &p.vertex_face {
        let t = x.kind.ipc_name();
        writeln!(
            out,
            "vf {} {} {:e} {t}",
            x.vertex, x.triangle, x.distance_sq
        )?;
    }
    for x in &p.face_vertex {
        let t = x.kind.ipc_name();
        writeln!(
            out,
            "fv {} {} {:e} {t}",
            x.triangle, x.vertex, x.distance_sq
        )?;
    }
    for x in &p.edge_edge {
        let (a, b, t) = (x.a, x.b, x.kind.ipc_name());
        writeln!(
            out,
            "ee {} {} {} {} {:e} {t}",
            a[0], a[1], b[0], b[1], x.distance_sq
        )?;
    }
    Ok(())
}
