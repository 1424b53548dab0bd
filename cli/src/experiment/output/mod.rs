//! Report writers: `report.json`, `report.md`, the SVG figures,
//! and the summary table printed by `dhcd experiment`.

pub mod svg;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde_json::{json, Value};

use super::{cost::Constant, MethodReport, RefitRow, RefitStudy, Report, Step, StepTotals};
use dhcd::bv::Method;
use dhcd::error::{Error, Result};
use dhcd::Refit;

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
            let mut v = step_json(s);
            v["predicted_ns"] = json!(s.predicted_ns);
            v["fixed_ns"] = json!(m.fixed_ns());
            v
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

/// A step's counters and times (the fields every variant has).
fn step_json(s: &Step) -> Value {
    json!({
        "bv_tests": s.counters.bv_tests,
        "prim_tests": s.counters.prim_tests,
        "bv_updates": s.counters.bv_updates,
        "contacts": s.counters.contacts,
        "time_ns": s.time_ns(),
        "update_ns": s.update_ns,
        "refit_ns": s.refit_ns,
        "query_ns": s.query_ns,
    })
}

/// The radius a refit mode fits.
fn radius_label(refit: Refit) -> &'static str {
    match refit {
        Refit::EagerBottomUp => "bottom-up bound",
        _ => "exact",
    }
}

fn study_json(study: &RefitStudy) -> Value {
    let l = &study.looseness;
    let rows: Vec<Value> = study
        .rows
        .iter()
        .map(|row| {
            let t = row.totals();
            json!({
                "refit": row.refit.name(),
                "radius": radius_label(row.refit),
                "totals": {
                    "bv_tests": t.bv_tests,
                    "prim_tests": t.prim_tests,
                    "bv_updates": t.bv_updates,
                    "contacts": t.contacts,
                    "update_ns": row.total_update_ns(),
                    "refit_ns": row.total_refit_ns(),
                    "query_ns": row.total_query_ns(),
                },
                "total_time_ns": row.total_time_ns(),
                "steps": row.steps.iter().map(step_json).collect::<Vec<_>>(),
            })
        })
        .collect();
    json!({
        "method": Method::Dh.name(),
        "baseline": "methods.dh (exact radius, lazy refit)",
        "looseness": {"internal_nodes": l.nodes, "mean": l.mean, "max": l.max, "root_mean": l.root_mean},
        "rows": rows,
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
            "central": s.central.name(),
            "threads": s.threads,
            "seed": s.seed,
            "snapshot_step": r.snapshot.step,
        },
        "methods": methods,
        "refit_study": r.refit_study.as_ref().map(study_json),
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
    if let Some(study) = &r.refit_study {
        let _ = writeln!(
            s,
            "\nDH radius (same frames): {:<16} {:>10} {:>12} {:>12} {:>10} {:>10} {:>10}",
            "radius, refit", "N_V", "N_P", "N_U", "refit ms", "query ms", "time ms"
        );
        for row in study_rows(r, study) {
            let _ = writeln!(
                s,
                "{:<24} {:<16} {:>10} {:>12} {:>12} {:>10} {:>10} {:>10}",
                "",
                format!("{}, {}", row.radius, row.refit),
                row.counters.bv_tests,
                row.counters.prim_tests,
                row.counters.bv_updates,
                row.refit_ms,
                ms(row.query_ns),
                ms(row.time_ns)
            );
        }
    }
    s
}

/// One row of the refit study's tables: the default lazy exact refit (DH's row of the
/// methods) or one of the study's eager modes.
struct StudyLine {
    radius: &'static str,
    refit: &'static str,
    counters: dhcd::Counters,
    /// Eager: measured; lazy: `N_U*C_U` (the refit is inside the query).
    refit_ms: String,
    update_ns: f64,
    query_ns: f64,
    time_ns: f64,
}

fn study_rows(r: &Report, study: &RefitStudy) -> Vec<StudyLine> {
    let mut rows = Vec::new();
    if let Some(dh) = r.method(Method::Dh) {
        let t = dh.totals();
        rows.push(StudyLine {
            radius: radius_label(Refit::Lazy),
            refit: "lazy (default)",
            counters: t,
            refit_ms: format!("~{}", ms(t.bv_updates as f64 * dh.costs.c_u.value)),
            update_ns: dh.total_update_ns(),
            query_ns: dh.total_query_ns(),
            time_ns: dh.total_time_ns(),
        });
    }
    rows.extend(study.rows.iter().map(|row: &RefitRow| StudyLine {
        radius: radius_label(row.refit),
        refit: "eager",
        counters: row.totals(),
        refit_ms: ms(row.total_refit_ns()),
        update_ns: row.total_update_ns(),
        query_ns: row.total_query_ns(),
        time_ns: row.total_time_ns(),
    }));
    rows
}

/// The refit study's section of the Markdown report.
fn study_markdown(md: &mut String, r: &Report, study: &RefitStudy) {
    let _ = writeln!(md, "\n## DH radius: exact against the bottom-up bound\n");
    let _ = writeln!(
        md,
        "The same frames, DH with the same central vertices ({}), refitted three ways: the default (the exact radius, lazily: a node's radius is recomputed from its region's vertices just before its first test in a step, inside the query), the exact radius of every node before the query (eager), and the bottom-up bound of every node before the query (eager: leaves exact, each internal node `r_p = max_c(|C_p - C_c| + r_c)` from its children; the paper's future work, cheaper radius updates). Contacts are identical (checked). Times are totals over the run of the least time over replays of each step; the lazy refit cannot be timed apart from the query, so its column is the calibrated `N_U·C_U`.\n",
        r.scene.central
    );
    let _ = writeln!(
        md,
        "| radius | refit | N_V (BV pairs) | N_P (triangle pairs) | N_U (BV updates) | contacts | update ms | refit ms | query ms | total ms |"
    );
    let _ = writeln!(md, "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    let rows = study_rows(r, study);
    for row in &rows {
        let c = row.counters;
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            row.radius,
            row.refit,
            c.bv_tests,
            c.prim_tests,
            c.bv_updates,
            c.contacts,
            ms(row.update_ns),
            row.refit_ms,
            ms(row.query_ns),
            ms(row.time_ns)
        );
    }
    let eager = |refit: Refit| study.rows.iter().find(|row| row.refit == refit);
    if let (Some(exact), Some(bound)) = (eager(Refit::Eager), eager(Refit::EagerBottomUp)) {
        let (e, b) = (exact.totals(), bound.totals());
        let ratio = |x: u64, y: u64| if y > 0 { x as f64 / y as f64 } else { 0.0 };
        let time_ratio = if exact.total_refit_ns() > 0.0 {
            bound.total_refit_ns() / exact.total_refit_ns()
        } else {
            0.0
        };
        let l = &study.looseness;
        let _ = writeln!(
            md,
            "\nThe bottom-up bound refits every node in {:.2}x the time of the exact eager refit; its looser radii cost {:.3}x the BV pairs (N_V) and {:.3}x the triangle pairs (N_P) of the exact radii. At the last step its radii are {:.3}x the exact ones on average over {} internal nodes (at most {:.3}x; {:.3}x at the roots).",
            time_ratio,
            ratio(b.bv_tests, e.bv_tests),
            ratio(b.prim_tests, e.prim_tests),
            l.mean,
            l.nodes,
            l.max,
            l.root_mean
        );
    }
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
        "Scene: {} objects ({}), {} triangles and {} vertices in all ({} / {} per object), {} nodes per hierarchy ({} levels), DH central vertex {}, {} frames, {} object pairs per step, {} thread(s), seed {}.\n",
        s.objects, s.mesh, s.triangles, s.vertices, s.triangles_per_object, s.vertices_per_object,
        s.nodes_per_hierarchy, s.levels, s.central, s.frames, s.object_pairs, s.threads, s.seed
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
    if let Some(study) = &r.refit_study {
        study_markdown(&mut md, r, study);
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
