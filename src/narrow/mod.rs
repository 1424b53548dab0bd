//! Exact narrow phase: closed triangle-triangle intersection decided exactly for f32 input.

/// Whether the closed triangles `a` and `b` share at least one point (exact).
pub fn triangles_intersect(a: &[[f32; 3]; 3], b: &[[f32; 3]; 3]) -> bool {
    let _ = (a, b);
    unimplemented!("narrow phase is being written")
}
