//! Report writers: `report.json`, `report.md`, the SVG figures,
//! and the summary table printed by `dhcd experiment`.

pub mod svg;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde_json::{json, Value};

use super::{cost::Constant, MethodReport, Report};
use dhcd::bv::Method;
use dhcd::error::{Error, Result};

/// Files written by [`write_all`], in order.
pub const FILES: [&str; 8] = [
    "report.json",
    "report.md",
    "fig1_scene.svg",
    "fig2_bv_tests.svg",
    "fig3_contacts.svg",
    "fig4_time.svg",
    "bv_updates.svg",
    "predicted_vs_measured.svg",
];

/// Colours of the methods' curves, by position in [`Method::ALL`] (wrapping around).
const PALETTE: [&str; 6] = [
    "#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b",
];

fn color(m: Method) -> &'static str {
    PALETTE[m.index() % PALETTE.len()]
}

fn spread_json(c: &Constant) -> Value {
    let s = &c.spread;
    json!({"median": s.median, "min": s.min, "max": s.max, "p25": s.p25, "p75": s.p75, "samples": s.samples})
}

fn method_json(m: &MethodReport) -> Value {
    let c = &m.costs;
    let t = m.totals();
    let steps: Vec<Value> = m
        .steps
        .iter()
        .map(|s| {
            json!({
                "bv_tests": s.counters.bv_tests,
                "prim_tests": s.counters.prim_tests,
                "bv_updates": s.counters.bv_updates,
                "contacts": s.counters.contacts,
                "time_ns": s.time_ns(),
                "predicted_ns": s.predicted_ns,
                "update_ns": s.update_ns,
                "query_ns": s.query_ns,
                "fixed_ns": m.fixed_ns(),
            })
        })
        .collect();
    json!({
        "bytes_per_node": m.bytes_per_node,
        "bytes_per_hierarchy": m.bytes_per_hierarchy,
        "bytes_all_hierarchies": m.bytes_all_hierarchies,
        "costs": {
            "c_v_ns": c.c_v.value,
            "c_p_ns": c.c_p.value,
            "c_u_ns": c.c_u.value,
            "fixed_ns_per_step": c.fixed_ns.value,
            "c_v_spread": spread_json(&c.c_v),
            "c_p_spread": spread_json(&c.c_p),
            "c_u_spread": spread_json(&c.c_u),
            "fixed_spread": spread_json(&c.fixed_ns),
            "per_frame": c.per_frame.iter().map(|f| json!({
                "frame": f.frame,
                "bv_tests": f.counters.bv_tests,
                "prim_tests": f.counters.prim_tests,
                "bv_updates": f.counters.bv_updates,
                "c_v_ns": f.c_v_ns,
                "c_p_ns": f.c_p_ns,
                "c_u_ns": f.c_u_ns,
                "fixed_ns": f.fixed_ns,
            })).collect::<Vec<_>>(),
        },
        "totals": {
            "bv_tests": t.bv_tests,
            "prim_tests": t.prim_tests,
            "bv_updates": t.bv_updates,
            "contacts": t.contacts,
            "update_ns": m.total_update_ns(),
            "query_ns": m.total_query_ns(),
        },
        "total_time_ns": m.total_time_ns(),
        "total_predicted_ns": m.total_predicted_ns(),
        "total_predicted_with_fixed_ns": m.total_predicted_with_fixed_ns(),
        "relative_error": m.model_error(),
        "relative_error_with_fixed": m.model_with_fixed_error(),
        "relative_error_vs_query": m.model_vs_query_error(),
        "steps": steps,
    })
}

/// The machine-readable report.
pub fn to_json(r: &Report) -> Value {
    let s = &r.scene;
    let mut methods = serde_json::Map::new();
    for m in &r.methods {
        methods.insert(m.method.name().into(), method_json(m));
    }
    json!({
        "scene": {
            "mesh": s.mesh,
            "objects": s.objects,
            "triangles": s.triangles,
            "vertices": s.vertices,
            "triangles_per_object": s.triangles_per_object,
            "vertices_per_object": s.vertices_per_object,
            "nodes_per_hierarchy": s.nodes_per_hierarchy,
            "object_pairs": s.object_pairs,
            "frames": s.frames,
            "levels": s.levels,
            "threads": s.threads,
            "seed": s.seed,
            "snapshot_step": r.snapshot.step,
        },
        "methods": methods,
        "wall_s": {"simulate": r.simulate_s, "measure": r.measure_s, "calibrate": r.calibrate_s},
    })
}

fn ms(ns: f64) -> String {
    format!("{:.1}", ns / 1e6)
}

fn pct(x: f64) -> String {
    format!("{:+.1}%", 100.0 * x)
}

/// The summary table (plain text, for stdout).
pub fn summary_table(r: &Report) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{:<7} {:>5} {:>12} {:>12} {:>10} {:>9} {:>10} {:>10} {:>10} {:>8}",
        "method",
        "B/BV",
        "N_V",
        "N_P",
        "N_U",
        "contacts",
        "time ms",
        "query ms",
        "model ms",
        "error"
    );
    for m in &r.methods {
        let t = m.totals();
        let _ = writeln!(
            s,
            "{:<7} {:>5} {:>12} {:>12} {:>10} {:>9} {:>10} {:>10} {:>10} {:>8}",
            m.method.name(),
            m.bytes_per_node,
            t.bv_tests,
            t.prim_tests,
            t.bv_updates,
            t.contacts,
            ms(m.total_time_ns()),
            ms(m.total_query_ns()),
            ms(m.total_predicted_ns()),
            pct(m.model_error())
        );
    }
    s
}

fn spread_cell(c: &Constant) -> String {
    let s = &c.spread;
    format!(
        "**{:.1}** (samples: median {:.1}, IQR {:.1}–{:.1}, range {:.1}–{:.1}, n={})",
        c.value, s.median, s.p25, s.p75, s.min, s.max, s.samples
    )
}

/// The human-readable report.
pub fn markdown(r: &Report) -> String {
    let s = &r.scene;
    let mut md = String::new();
    let _ = writeln!(md, "# dhcd experiment report\n");
    let _ = writeln!(
        md,
        "Scene: {} objects ({}), {} triangles and {} vertices in all ({} / {} per object), {} nodes per hierarchy ({} levels), {} frames, {} object pairs per step, {} thread(s), seed {}.\n",
        s.objects, s.mesh, s.triangles, s.vertices, s.triangles_per_object, s.vertices_per_object,
        s.nodes_per_hierarchy, s.levels, s.frames, s.object_pairs, s.threads, s.seed
    );
    let _ = writeln!(
        md,
        "Wall time: simulate {:.1} s, measure {:.1} s, calibrate {:.1} s. Step times are the least over replays of the step (the machine is shared).\n",
        r.simulate_s, r.measure_s, r.calibrate_s
    );
    let _ = writeln!(md, "## Per-method totals over all steps\n");
    let _ = writeln!(
        md,
        "| method | N_V (BV pairs) | N_P (triangle pairs) | N_U (BV updates) | contacts | update ms | query ms | total ms |"
    );
    let _ = writeln!(md, "|---|---:|---:|---:|---:|---:|---:|---:|");
    for m in &r.methods {
        let t = m.totals();
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} | {} | {} |",
            m.method.label(),
            t.bv_tests,
            t.prim_tests,
            t.bv_updates,
            t.contacts,
            ms(m.total_update_ns()),
            ms(m.total_query_ns()),
            ms(m.total_time_ns())
        );
    }
    let _ = writeln!(md, "\n## Cost constants (ns per operation)\n");
    let _ = writeln!(
        md,
        "Constant = sum over calibration frames of the least time (over repetitions) / sum of the counts. Spread: every single sample time/count, over all calibration frames and repetitions.\n"
    );
    let _ = writeln!(
        md,
        "| method | C_V | C_P | C_U | fixed per step (update_positions) |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|");
    for m in &r.methods {
        let c = &m.costs;
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {:.0} ns (range {:.0}–{:.0}) |",
            m.method.label(),
            spread_cell(&c.c_v),
            spread_cell(&c.c_p),
            spread_cell(&c.c_u),
            c.fixed_ns.value,
            c.fixed_ns.spread.min,
            c.fixed_ns.spread.max
        );
    }
    let _ = writeln!(
        md,
        "\nPer calibration frame (least time over repetitions / count):\n"
    );
    let _ = writeln!(md, "| method | frame | N_V | N_P | N_U | C_V | C_P | C_U |");
    let _ = writeln!(md, "|---|---:|---:|---:|---:|---:|---:|---:|");
    for m in &r.methods {
        for f in &m.costs.per_frame {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {:.1} | {:.1} | {:.1} |",
                m.method.label(),
                f.frame,
                f.counters.bv_tests,
                f.counters.prim_tests,
                f.counters.bv_updates,
                f.c_v_ns,
                f.c_p_ns,
                f.c_u_ns
            );
        }
    }
    let _ = writeln!(md, "\n## Predicted vs measured (whole run)\n");
    let _ = writeln!(
        md,
        "Model = N_V·C_V + N_P·C_P + N_U·C_U. Measured = update + query. The fixed term is the calibrated `update_positions` cost (position copy into the internal order, O(V)), which the paper's model does not have.\n"
    );
    let _ = writeln!(
        md,
        "| method | N_V·C_V ms | N_P·C_P ms | N_U·C_U ms | model ms | measured ms | error | fixed ms | model + fixed ms | error | query ms | model vs query |"
    );
    let _ = writeln!(
        md,
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for m in &r.methods {
        let t = m.totals();
        let c = &m.costs;
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            m.method.label(),
            ms(t.bv_tests as f64 * c.c_v.value),
            ms(t.prim_tests as f64 * c.c_p.value),
            ms(t.bv_updates as f64 * c.c_u.value),
            ms(m.total_predicted_ns()),
            ms(m.total_time_ns()),
            pct(m.model_error()),
            ms(m.fixed_ns() * m.steps.len() as f64),
            ms(m.total_predicted_with_fixed_ns()),
            pct(m.model_with_fixed_error()),
            ms(m.total_query_ns()),
            pct(m.model_vs_query_error())
        );
    }
    let _ = writeln!(md, "\n## Memory\n");
    let _ = writeln!(
        md,
        "| method | bytes per BV | bytes per hierarchy | all hierarchies |"
    );
    let _ = writeln!(md, "|---|---:|---:|---:|");
    for m in &r.methods {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} |",
            m.method.label(),
            m.bytes_per_node,
            m.bytes_per_hierarchy,
            m.bytes_all_hierarchies
        );
    }
    let _ = writeln!(md, "\n## Figures\n");
    for (f, cap) in [
        (
            "fig1_scene.svg",
            "Figure 1: the scene at the step with most contacts (contacts in red)",
        ),
        ("fig2_bv_tests.svg", "Figure 2: BV pairs tested per step"),
        ("fig3_contacts.svg", "Figure 3: contacts per step"),
        ("fig4_time.svg", "Figure 4: time per step"),
        ("bv_updates.svg", "BV updates per step"),
        (
            "predicted_vs_measured.svg",
            "Cost model vs measured time per step",
        ),
    ] {
        let _ = writeln!(md, "![{cap}]({f})\n");
    }
    md
}

fn per_step(r: &Report, f: impl Fn(&MethodReport, usize) -> f64) -> Vec<svg::Series<'static>> {
    r.methods
        .iter()
        .map(|m| svg::Series {
            name: m.method.label(),
            color: color(m.method),
            dashed: false,
            values: (0..m.steps.len()).map(|i| f(m, i)).collect(),
        })
        .collect()
}

/// The SVG figures as `(file name, contents)`.
pub fn figures(r: &Report) -> Vec<(&'static str, String)> {
    let snap = &r.snapshot;
    let n_contacts: usize = snap.contact_triangles.iter().map(Vec::len).sum();
    let mut pvm = Vec::new();
    for m in &r.methods {
        pvm.push(svg::Series {
            name: m.method.label(),
            color: color(m.method),
            dashed: false,
            values: m.steps.iter().map(|s| s.time_ns() / 1e6).collect(),
        });
        pvm.push(svg::Series {
            name: "  model",
            color: color(m.method),
            dashed: true,
            values: m.steps.iter().map(|s| s.predicted_ns / 1e6).collect(),
        });
    }
    vec![
        (
            "fig1_scene.svg",
            svg::scene(
                snap,
                &format!(
                    "Step {}: {} objects, {} triangles in contact (red)",
                    snap.step,
                    snap.positions.len(),
                    n_contacts
                ),
            ),
        ),
        (
            "fig2_bv_tests.svg",
            svg::line_chart(
                "BV pairs tested per step (N_V)",
                "step",
                "BV pairs tested",
                &per_step(r, |m, i| m.steps[i].counters.bv_tests as f64),
            ),
        ),
        (
            "fig3_contacts.svg",
            svg::line_chart(
                "Contacts (intersecting triangle pairs) per step",
                "step",
                "contacts",
                &per_step(r, |m, i| m.steps[i].counters.contacts as f64),
            ),
        ),
        (
            "fig4_time.svg",
            svg::line_chart(
                "Time per step (update + query)",
                "step",
                "ms",
                &per_step(r, |m, i| m.steps[i].time_ns() / 1e6),
            ),
        ),
        (
            "bv_updates.svg",
            svg::line_chart(
                "BV updates per step (N_U)",
                "step",
                "BV updates",
                &per_step(r, |m, i| m.steps[i].counters.bv_updates as f64),
            ),
        ),
        (
            "predicted_vs_measured.svg",
            svg::line_chart(
                "Measured time (solid) vs N_V·C_V + N_P·C_P + N_U·C_U (dashed)",
                "step",
                "ms",
                &pvm,
            ),
        ),
    ]
}

/// Writes every file of [`FILES`] into `dir` (created if needed); returns their paths.
pub fn write_all(r: &Report, dir: &Path) -> Result<Vec<PathBuf>> {
    let io = |path: &Path, e: std::io::Error| Error::Io {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    std::fs::create_dir_all(dir).map_err(|e| io(dir, e))?;
    let json = serde_json::to_string_pretty(&to_json(r)).map_err(|e| Error::Io {
        path: dir.join("report.json"),
        message: e.to_string(),
    })?;
    let mut files = vec![("report.json", json), ("report.md", markdown(r))];
    files.extend(figures(r));
    let mut written = Vec::new();
    for (name, text) in files {
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(|e| io(&path, e))?;
        written.push(path);
    }
    Ok(written)
}
