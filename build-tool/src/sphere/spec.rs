//! The direction density SPECs (`uniform`, `cosine`, `brdf:ROUGHNESS,THETA_O_DEG`,
//! `envmap:PATH`) and their parser, which builds each target of this module.

use super::brdf_target::BrdfTarget;
use super::closed_form::{CosineDirections, UniformDirections};
use super::envmap::EnvmapDensity;
use super::target::{DirectionDensity, DirectionSpecError};
use crate::density::{split_params, SpecFamily, SpecSyntaxError};
use nuld_core::blob::Domain;
use nuld_core::brdf::BrdfModel;

/// Parses a direction density SPEC for `domain`
/// ([`Domain::Sphere`] or [`Domain::Hemisphere`]):
///
/// * `uniform` — uniform on the domain (on the hemisphere: over `z >= 0`);
/// * `cosine` — `∝ max(z, 0)` (the same on both domains);
/// * `brdf:ROUGHNESS,THETA_O_DEG` — `∝ f(wo, wi) max(n.wi, 0)` of the glTF 2.0 BRDF
///   ([`nuld_core::brdf`]) with `wo = view_direction(THETA_O_DEG)`;
///   ROUGHNESS in `[0.1, 1]`, THETA_O_DEG in `[0, 89]`;
/// * `brdf-burley:ROUGHNESS,THETA_O_DEG` — the same with Burley's 2012 BRDF
///   ([`BrdfModel::Burley`]), same ranges;
/// * `envmap:PATH` — equirectangular luminance map, `+z` up (everything after the
///   first `:` is the path). On the hemisphere domain the map is cut at the horizon.
///
/// The kind is matched exactly; whitespace around it and the numbers is ignored.
/// Building `brdf` costs a few tens of ms (normalizer and tables), `envmap` the
/// decode plus `O(W H)`.
pub fn parse_direction_spec(
    spec: &str,
    domain: Domain,
) -> Result<Box<dyn DirectionDensity>, DirectionSpecError> {
    let spec = spec.trim();
    if spec.is_empty() {
        return Err(SpecSyntaxError::Empty {
            family: SpecFamily::Direction,
        }
        .into());
    }
    if domain == Domain::Square {
        return Err(DirectionSpecError::SquareDomain {
            spec: spec.to_string(),
        });
    }
    let (kind, rest) = match spec.split_once(':') {
        Some((k, r)) => (k.trim(), Some(r)),
        None => (spec, None),
    };
    let hemisphere = domain == Domain::Hemisphere;
    match kind {
        "uniform" => {
            params("uniform", "uniform", &[], rest)?;
            Ok(Box::new(UniformDirections { hemisphere }))
        }
        "cosine" => {
            params("cosine", "cosine", &[], rest)?;
            Ok(Box::new(CosineDirections { hemisphere }))
        }
        "brdf" => {
            // METALLIC is optional: two numbers are the dielectric.
            let names: &[&'static str] = match rest.map_or(0, |r| r.matches(',').count()) {
                2 => &["ROUGHNESS", "THETA_O_DEG", "METALLIC"],
                _ => &["ROUGHNESS", "THETA_O_DEG"],
            };
            let p = params("brdf", "brdf:ROUGHNESS,THETA_O_DEG[,METALLIC]", names, rest)?;
            let metallic = p.get(2).copied().unwrap_or(0.0);
            Ok(Box::new(BrdfTarget::metallic(
                p[0], p[1], metallic, domain,
            )?))
        }
        "brdf-burley" => {
            let p = params(
                "brdf-burley",
                "brdf-burley:ROUGHNESS,THETA_O_DEG",
                &["ROUGHNESS", "THETA_O_DEG"],
                rest,
            )?;
            Ok(Box::new(BrdfTarget::with_model(
                BrdfModel::Burley,
                p[0],
                p[1],
                domain,
            )?))
        }
        "envmap" => {
            let path = rest.unwrap_or("");
            if path.trim().is_empty() {
                return Err(DirectionSpecError::EmptyPath);
            }
            Ok(Box::new(EnvmapDensity::from_file(path, domain)?))
        }
        other => Err(SpecSyntaxError::UnknownKind {
            family: SpecFamily::Direction,
            kind: other.to_string(),
        }
        .into()),
    }
}

/// Parses the comma-separated numbers of `kind` (range checks are the caller's).
fn params(
    kind: &'static str,
    usage: &'static str,
    names: &[&'static str],
    text: Option<&str>,
) -> Result<Vec<f64>, DirectionSpecError> {
    Ok(split_params(
        SpecFamily::Direction,
        kind,
        usage,
        names,
        text,
    )?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn specs_parse_and_errors_are_one_line() {
        for (s, d) in [
            ("uniform", Domain::Sphere),
            (" cosine ", Domain::Hemisphere),
            ("brdf:0.5, 30", Domain::Hemisphere),
            ("brdf-burley:0.5,30", Domain::Hemisphere),
        ] {
            let den = parse_direction_spec(s, d).unwrap();
            assert_eq!(den.domain(), d);
            assert!(!den.spec().contains(' '));
        }
        assert_eq!(
            parse_direction_spec("brdf:0.5,30", Domain::Hemisphere)
                .unwrap()
                .spec(),
            "brdf:0.5,30"
        );
        let bad = [
            ("", "empty"),
            (
                "gaussian:1,2,3",
                "unknown direction density spec kind `gaussian`",
            ),
            ("uniform:3", "takes 0 parameter"),
            (
                "brdf:0.5",
                "takes 2 parameter(s) (brdf:ROUGHNESS,THETA_O_DEG[,METALLIC]), got 1",
            ),
            ("brdf:x,30", "ROUGHNESS = `x` is not a number"),
            ("brdf:0.09,30", "ROUGHNESS = 0.09 is outside [0.1, 1]"),
            ("brdf:1.5,30", "ROUGHNESS = 1.5 is outside"),
            ("brdf:nan,30", "ROUGHNESS = NaN is outside"),
            ("brdf:0.5,89.5", "THETA_O_DEG = 89.5 is outside [0, 89]"),
            (
                "brdf-burley:0.05,30",
                "`brdf-burley`: parameter ROUGHNESS = 0.05",
            ),
            (
                "brdf-burley:1",
                "takes 2 parameter(s) (brdf-burley:ROUGHNESS,THETA_O_DEG)",
            ),
            ("brdf:0.5,-1", "THETA_O_DEG = -1 is outside"),
            ("envmap:", "needs a file path"),
            ("envmap:/nonexistent/x.hdr", "not found"),
        ];
        for (s, want) in bad {
            let e = parse_direction_spec(s, Domain::Sphere)
                .err()
                .unwrap()
                .to_string();
            assert!(e.contains(want), "{s}: {e}");
            assert!(!e.contains('\n'));
        }
        let e = parse_direction_spec("uniform", Domain::Square)
            .err()
            .unwrap();
        assert!(e.to_string().contains("not the square"));
        // An undecodable file.
        let dir = std::env::temp_dir().join(format!("nuld-sphere-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("junk.hdr");
        std::fs::write(&f, b"this is not an image").unwrap();
        let e = parse_direction_spec(&format!("envmap:{}", f.display()), Domain::Sphere)
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("cannot decode"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
