//! The BRDF conditions that examples take on their command line:
//! `roughness,view°,metallic` triples separated by `/`, e.g. `0.1,75,0/0.1,75,1`.

/// The conditions of `list`; exits with a one-line message on a malformed one.
pub fn parse(list: &str) -> Vec<[f64; 3]> {
    (list.split('/'))
        .map(|c| {
            let v: Vec<f64> = (c.split(','))
                .filter_map(|x| x.trim().parse().ok())
                .collect();
            match v[..] {
                [r, t, m] => [r, t, m],
                _ => {
                    eprintln!("condition {c:?}: expected roughness,view°,metallic");
                    std::process::exit(2);
                }
            }
        })
        .collect()
}
