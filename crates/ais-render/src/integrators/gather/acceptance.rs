//! Roulette's acceptance rules: how a candidate's acceptance probability follows from the
//! map's affinity and, for the value-aware rules, from what the candidate would bring.

/// How a candidate's acceptance probability follows from the map's affinity `q` and, for
/// the value-aware rules, the candidate's unoccluded contribution `v` (luminance of
/// f·L/p with nothing in the way, known before tracing) and the mean `v̄` of the batch's
/// earlier candidates. Every rule is exactly unbiased (the traced ray weighs 1/acceptance).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Acceptance {
    /// The talk's: `q`.
    Affinity,
    /// `√q`: efficiency-optimised roulette when the candidate's value is not known (and so
    /// costs nothing to decide). A rejected candidate still costs a proposal sample, so
    /// rejecting in proportion to `q` draws too many of them; `√q` balances the two costs.
    SqrtAffinity,
    /// `1` when `v > 2 v̄` (never skip a bright candidate), else `q`.
    ValueThreshold,
    /// Efficiency-optimised Russian roulette: `clamp(√q · v / v̄, 10⁻³, 1)`, the
    /// variance-per-cost optimum for a candidate worth `v` with probability `q`.
    ValueEfficient,
}

/// [`Acceptance::ValueThreshold`] traces every candidate brighter than this many times the
/// mean unoccluded contribution of the batch's earlier candidates.
pub const VALUE_THRESHOLD: f32 = 2.0;

impl Acceptance {
    /// Parses a rule's name: "affinity", "sqrt", "value" or "efficient".
    pub fn parse(name: &str) -> Option<Acceptance> {
        match name {
            "affinity" => Some(Acceptance::Affinity),
            "value" => Some(Acceptance::ValueThreshold),
            "efficient" => Some(Acceptance::ValueEfficient),
            "sqrt" => Some(Acceptance::SqrtAffinity),
            _ => None,
        }
    }

    /// Its name, as [`Acceptance::parse`] reads it.
    pub fn name(self) -> &'static str {
        match self {
            Acceptance::Affinity => "affinity",
            Acceptance::SqrtAffinity => "sqrt",
            Acceptance::ValueThreshold => "value",
            Acceptance::ValueEfficient => "efficient",
        }
    }

    /// Whether the rule needs the candidate's unoccluded value (and so its density, the
    /// BSDF and the lights) before deciding.
    pub fn needs_value(self) -> bool {
        matches!(
            self,
            Acceptance::ValueThreshold | Acceptance::ValueEfficient
        )
    }

    /// The acceptance probability for affinity `q`, value `v` and earlier mean `mean`
    /// (`v` and `mean` matter only to the rules that [`Acceptance::needs_value`]).
    pub(crate) fn probability(self, q: f32, v: f32, mean: Option<f32>) -> f32 {
        match (self, mean) {
            (Acceptance::Affinity, _) => q,
            (Acceptance::SqrtAffinity, _) => q.sqrt(),
            // The first candidate has no mean to compare with: trace it.
            (_, None) => 1.0,
            (Acceptance::ValueThreshold, Some(mean)) => {
                if v > VALUE_THRESHOLD * mean {
                    1.0
                } else {
                    q
                }
            }
            (Acceptance::ValueEfficient, Some(mean)) => {
                if mean > 0.0 {
                    (q.sqrt() * v / mean).clamp(1e-3, 1.0)
                } else {
                    1.0
                }
            }
        }
    }
}
