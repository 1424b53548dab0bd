//! The real simulation frames' file names, shared by the benches that read them.

/// Pairs `(N, N+1)` of frames `<name>-<number>.ply` in `dir`, in name order.
pub fn frame_pairs(dir: &std::path::Path) -> Vec<(String, String)> {
    let mut by_name: std::collections::BTreeMap<String, Vec<u64>> =
        std::collections::BTreeMap::new();
    for entry in std::fs::read_dir(dir).expect("readable data folder") {
        let file = entry.expect("readable entry").file_name();
        let Some(stem) = file.to_str().and_then(|f| f.strip_suffix(".ply")) else {
            continue;
        };
        if let Some((name, number)) = stem.rsplit_once('-') {
            if let Ok(number) = number.parse() {
                by_name.entry(name.to_owned()).or_default().push(number);
            }
        }
    }
    let mut pairs = Vec::new();
    for (name, mut numbers) in by_name {
        numbers.sort_unstable();
        for w in numbers.windows(2).filter(|w| w[1] == w[0] + 1) {
            pairs.push((format!("{name}-{}", w[0]), format!("{name}-{}", w[1])));
        }
    }
    pairs
}
