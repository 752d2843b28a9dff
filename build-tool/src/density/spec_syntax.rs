//! The SPEC grammar shared by the square and the direction targets,
//! `KIND[:P1,P2,...]`, and its errors: one definition for both families, whose
//! messages differ only in the family's name and the kinds it lists.

/// The two families of target SPECs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpecFamily {
    /// Densities on the unit square (`--density` with `--domain square`).
    Square,
    /// Densities of directions on the sphere or hemisphere.
    Direction,
}

impl SpecFamily {
    /// How messages name a target of the family.
    pub fn noun(self) -> &'static str {
        match self {
            Self::Square => "density",
            Self::Direction => "direction density",
        }
    }

    /// What an empty SPEC's message suggests.
    fn empty_hint(self) -> &'static str {
        match self {
            Self::Square => "e.g. `uniform` or `gaussian:0.5,0.5,0.15`",
            Self::Direction => Self::DIRECTION_KINDS,
        }
    }

    /// The kinds an unknown kind's message lists.
    fn kinds(self) -> &'static str {
        match self {
            Self::Square => {
                "uniform, gaussian:MX,MY,SIGMA, bilinear:V00,V10,V01,V11, quarter-disc, \
                 step-gaussian or image:PATH"
            }
            Self::Direction => Self::DIRECTION_KINDS,
        }
    }

    const DIRECTION_KINDS: &'static str =
        "uniform, cosine, brdf:ROUGHNESS,THETA_O_DEG, brdf-burley:ROUGHNESS,THETA_O_DEG or envmap:PATH";
}

/// A SPEC that does not follow the grammar. `Display` is one line.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SpecSyntaxError {
    /// The SPEC is empty (or only whitespace).
    #[error("empty {} spec (expected {})", family.noun(), family.empty_hint())]
    Empty {
        /// The family asked for.
        family: SpecFamily,
    },
    /// The part before `:` names no kind of the family.
    #[error("unknown {} spec kind `{kind}` (expected {})", family.noun(), family.kinds())]
    UnknownKind {
        /// The family asked for.
        family: SpecFamily,
        /// The kind as written.
        kind: String,
    },
    /// Wrong number of comma-separated parameters.
    #[error("{} `{kind}` takes {expected} parameter(s) ({usage}), got {got}", family.noun())]
    ParamCount {
        /// The family asked for.
        family: SpecFamily,
        /// The kind.
        kind: &'static str,
        /// Usage, e.g. `gaussian:MX,MY,SIGMA`.
        usage: &'static str,
        /// Parameters the kind takes.
        expected: usize,
        /// Parameters given.
        got: usize,
    },
    /// A parameter does not parse as a number.
    #[error("{} `{kind}`: parameter {param} = `{text}` is not a number", family.noun())]
    NotANumber {
        /// The family asked for.
        family: SpecFamily,
        /// The kind.
        kind: &'static str,
        /// Parameter name.
        param: &'static str,
        /// The text as written.
        text: String,
    },
}

/// The numbers of kind `kind`'s parameter list `text` (after the `:`), one per name
/// in `names`; no list, or an empty one, is zero parameters. Range checks are the
/// caller's.
pub(crate) fn split_params(
    family: SpecFamily,
    kind: &'static str,
    usage: &'static str,
    names: &[&'static str],
    text: Option<&str>,
) -> Result<Vec<f64>, SpecSyntaxError> {
    let parts: Vec<&str> = match text.map(str::trim) {
        None | Some("") => Vec::new(),
        Some(t) => t.split(',').map(str::trim).collect(),
    };
    if parts.len() != names.len() {
        return Err(SpecSyntaxError::ParamCount {
            family,
            kind,
            usage,
            expected: names.len(),
            got: parts.len(),
        });
    }
    parts
        .iter()
        .zip(names)
        .map(|(&text, &param)| {
            text.parse::<f64>()
                .map_err(|_| SpecSyntaxError::NotANumber {
                    family,
                    kind,
                    param,
                    text: text.to_string(),
                })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parameters_split_and_errors_name_the_family() {
        let f = SpecFamily::Direction;
        let two = ["A", "B"];
        assert_eq!(
            split_params(f, "k", "k:A,B", &two, Some(" 1, -2.5 ")),
            Ok(vec![1.0, -2.5])
        );
        assert_eq!(split_params(f, "k", "k", &[], None), Ok(vec![]));
        assert_eq!(split_params(f, "k", "k", &[], Some("  ")), Ok(vec![]));
        let e = split_params(f, "k", "k:A,B", &two, Some("1")).unwrap_err();
        assert_eq!(
            e.to_string(),
            "direction density `k` takes 2 parameter(s) (k:A,B), got 1"
        );
        let e = split_params(SpecFamily::Square, "k", "k:A,B", &two, Some("1,x")).unwrap_err();
        assert_eq!(
            e.to_string(),
            "density `k`: parameter B = `x` is not a number"
        );
        let e = SpecSyntaxError::UnknownKind {
            family: SpecFamily::Square,
            kind: "gauss".into(),
        };
        assert!(e
            .to_string()
            .starts_with("unknown density spec kind `gauss` (expected uniform,"));
    }
}
