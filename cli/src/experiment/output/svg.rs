//! Hand-written SVG: line charts of per-step series, and the scene picture (Figure 1).

use std::fmt::Write;

use glam::Vec3;

use crate::experiment::Snapshot;

/// One line of a chart.
pub struct Series<'a> {
    pub name: &'a str,
    pub color: &'a str,
    pub dashed: bool,
    pub values: Vec<f64>,
}

const W: f64 = 760.0;
const H: f64 = 440.0;
const LEFT: f64 = 80.0;
const RIGHT: f64 = 150.0;
const TOP: f64 = 40.0;
const BOTTOM: f64 = 55.0;

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// A "nice" step (1, 2 or 5 times a power of ten) giving about `ticks` intervals over `span`.
fn nice_step(span: f64, ticks: f64) -> f64 {
    let raw = (span / ticks).max(f64::MIN_POSITIVE);
    let p = 10f64.powf(raw.log10().floor());
    let m = raw / p;
    p * if m <= 1.0 {
        1.0
    } else if m <= 2.0 {
        2.0
    } else if m <= 5.0 {
        5.0
    } else {
        10.0
    }
}

fn fmt_tick(v: f64) -> String {
    let a = v.abs();
    if a >= 1e6 {
        format!("{}M", trim(v / 1e6))
    } else if a >= 1e4 {
        format!("{}k", trim(v / 1e3))
    } else {
        trim(v)
    }
}

fn trim(v: f64) -> String {
    let s = format!("{v:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}

/// A line chart of per-step values (x = step index from 0).
pub fn line_chart(title: &str, x_label: &str, y_label: &str, series: &[Series]) -> String {
    let n = series
        .iter()
        .map(|s| s.values.len())
        .max()
        .unwrap_or(0)
        .max(2);
    let y_max = series
        .iter()
        .flat_map(|s| s.values.iter().copied())
        .filter(|v| v.is_finite())
        .fold(0.0f64, f64::max);
    let y_step = nice_step(if y_max > 0.0 { y_max } else { 1.0 }, 5.0);
    let y_top = (y_max / y_step).ceil().max(1.0) * y_step;
    let (pw, ph) = (W - LEFT - RIGHT, H - TOP - BOTTOM);
    let x_of = |i: f64| LEFT + pw * i / (n - 1) as f64;
    let y_of = |v: f64| TOP + ph * (1.0 - v / y_top);
    let mut s = String::new();
    let _ = write!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" viewBox="0 0 {W} {H}" font-family="sans-serif" font-size="12">
<rect width="100%" height="100%" fill="white"/>
<text x="{}" y="22" text-anchor="middle" font-size="15">{}</text>
"#,
        LEFT + pw / 2.0,
        esc(title)
    );
    // Grid and y ticks.
    let mut v = 0.0;
    while v <= y_top * (1.0 + 1e-9) {
        let y = y_of(v);
        let _ = writeln!(
            s,
            r##"<line x1="{LEFT}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#e4e4e4"/><text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"##,
            LEFT + pw,
            LEFT - 6.0,
            y + 4.0,
            fmt_tick(v)
        );
        v += y_step;
    }
    // x ticks.
    let x_step = nice_step((n - 1) as f64, 8.0).max(1.0);
    let mut x = 0.0;
    while x <= (n - 1) as f64 + 1e-9 {
        let px = x_of(x);
        let _ = writeln!(
            s,
            r##"<line x1="{px:.1}" y1="{:.1}" x2="{px:.1}" y2="{:.1}" stroke="#999"/><text x="{px:.1}" y="{:.1}" text-anchor="middle">{}</text>"##,
            TOP + ph,
            TOP + ph + 5.0,
            TOP + ph + 19.0,
            fmt_tick(x)
        );
        x += x_step;
    }
    let _ = writeln!(
        s,
        r##"<rect x="{LEFT}" y="{TOP}" width="{pw}" height="{ph}" fill="none" stroke="#444"/>
<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text>
<text transform="translate(18,{:.1}) rotate(-90)" text-anchor="middle">{}</text>"##,
        LEFT + pw / 2.0,
        H - 12.0,
        esc(x_label),
        TOP + ph / 2.0,
        esc(y_label)
    );
    for (k, ser) in series.iter().enumerate() {
        let mut d = String::new();
        for (i, &v) in ser.values.iter().enumerate() {
            let v = if v.is_finite() { v } else { 0.0 };
            let _ = write!(
                d,
                "{}{:.1} {:.1}",
                if i == 0 { "M" } else { "L" },
                x_of(i as f64),
                y_of(v)
            );
        }
        let dash = if ser.dashed {
            r#" stroke-dasharray="6 4""#
        } else {
            ""
        };
        let _ = writeln!(
            s,
            r#"<path d="{d}" fill="none" stroke="{}" stroke-width="1.8"{dash}/>"#,
            ser.color
        );
        let ly = TOP + 14.0 + 20.0 * k as f64;
        let lx = LEFT + pw + 12.0;
        let _ = writeln!(
            s,
            r#"<line x1="{lx}" y1="{ly}" x2="{}" y2="{ly}" stroke="{}" stroke-width="2"{dash}/><text x="{}" y="{}">{}</text>"#,
            lx + 24.0,
            ser.color,
            lx + 30.0,
            ly + 4.0,
            esc(ser.name)
        );
    }
    s.push_str("</svg>\n");
    s
}

/// Base colours of the objects (RGB).
const PALETTE: [[f32; 3]; 8] = [
    [0.85, 0.80, 0.70],
    [0.35, 0.33, 0.32],
    [0.80, 0.75, 0.62],
    [0.42, 0.38, 0.36],
    [0.88, 0.84, 0.74],
    [0.30, 0.29, 0.30],
    [0.78, 0.72, 0.60],
    [0.45, 0.41, 0.38],
];

/// The scene at `snap.step`, orthographic oblique view (from the front, above), flat shaded,
/// back faces culled, painter's algorithm; triangles in contact in red.
pub fn scene(snap: &Snapshot, title: &str) -> String {
    // View: turn 30 degrees about y, tilt 25 degrees down; y is up.
    let (sy, cy) = 0.52f32.sin_cos();
    let (sx, cx) = 0.44f32.sin_cos();
    let view = |p: [f32; 3]| {
        let v = Vec3::from(p);
        let a = Vec3::new(cy * v.x + sy * v.z, v.y, -sy * v.x + cy * v.z);
        // Tilt: the camera looks down; depth grows away from the viewer.
        Vec3::new(a.x, cx * a.y - sx * a.z, sx * a.y + cx * a.z)
    };
    let light = Vec3::new(-0.4, 0.7, -0.6).normalize();
    struct Tri {
        depth: f32,
        pts: [[f32; 2]; 3],
        color: [u8; 3],
    }
    let mut tris = Vec::new();
    let (mut lo, mut hi) = ([f32::INFINITY; 2], [f32::NEG_INFINITY; 2]);
    for (o, (pos, tri)) in snap.positions.iter().zip(&snap.triangles).enumerate() {
        let vp: Vec<Vec3> = pos.iter().map(|&p| view(p)).collect();
        let contact = &snap.contact_triangles[o];
        for (t, &[a, b, c]) in tri.iter().enumerate() {
            let (pa, pb, pc) = (vp[a as usize], vp[b as usize], vp[c as usize]);
            let nrm = (pb - pa).cross(pc - pa);
            let in_contact = contact.binary_search(&(t as u32)).is_ok();
            // Camera looks along +z (view space); front faces have normal.z < 0.
            if nrm.z >= 0.0 && !in_contact {
                continue;
            }
            let nrm = nrm.normalize_or_zero();
            // Quantised so that neighbouring triangles share a colour (and a path element).
            let shade = ((0.35 + 0.65 * nrm.dot(-light).abs()) * 16.0).round() / 16.0;
            let base = if in_contact {
                [0.9, 0.1, 0.1]
            } else {
                PALETTE[o % PALETTE.len()]
            };
            let color = base.map(|x| ((x * shade).clamp(0.0, 1.0) * 255.0) as u8);
            let pts = [pa, pb, pc].map(|p| [p.x, -p.y]);
            for p in &pts {
                for k in 0..2 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
            // Contacts drawn slightly in front so that they stay visible.
            let bias = if in_contact { 1e-3 } else { 0.0 };
            tris.push(Tri {
                depth: (pa.z + pb.z + pc.z) / 3.0 - bias,
                pts,
                color,
            });
        }
    }
    tris.sort_by(|a, b| b.depth.total_cmp(&a.depth));
    let (w, h) = (900.0f32, 560.0f32);
    let margin = 20.0;
    let span = [(hi[0] - lo[0]).max(1e-9), (hi[1] - lo[1]).max(1e-9)];
    let scale = ((w - 2.0 * margin) / span[0]).min((h - 2.0 * margin - 30.0) / span[1]);
    let ox = margin + 0.5 * (w - 2.0 * margin - scale * span[0]);
    let oy = margin + 30.0 + 0.5 * (h - 2.0 * margin - 30.0 - scale * span[1]);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="14">
<rect width="100%" height="100%" fill="white"/>
<text x="{}" y="24" text-anchor="middle">{}</text>"#,
        w / 2.0,
        esc(title)
    );
    // One CSS class per colour; consecutive triangles of one colour share a path element;
    // whole-pixel coordinates (the stroke in the fill colour hides the seams).
    let mut colors: Vec<[u8; 3]> = tris.iter().map(|t| t.color).collect();
    colors.sort_unstable();
    colors.dedup();
    s.push_str("<style>path{stroke-width:0.6;stroke-linejoin:round}");
    for (i, c) in colors.iter().enumerate() {
        let _ = write!(
            s,
            ".c{i}{{fill:#{0:02x}{1:02x}{2:02x};stroke:#{0:02x}{1:02x}{2:02x}}}",
            c[0], c[1], c[2]
        );
    }
    s.push_str("</style>\n");
    let mut k = 0;
    while k < tris.len() {
        let c = tris[k].color;
        let class = colors.binary_search(&c).unwrap_or(0);
        let _ = write!(s, r#"<path class="c{class}" d=""#);
        while k < tris.len() && tris[k].color == c {
            for (i, p) in tris[k].pts.iter().enumerate() {
                let x = ox + (p[0] - lo[0]) * scale;
                let y = oy + (p[1] - lo[1]) * scale;
                let _ = write!(s, "{}{:.0} {:.0}", if i == 0 { "M" } else { "L" }, x, y);
            }
            s.push('Z');
            k += 1;
        }
        s.push_str("\"/>\n");
    }
    s.push_str("</svg>\n");
    s
}
