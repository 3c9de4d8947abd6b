//! Algorithm 2, minimum-angle improvement (Sec. 3.4), after the loop of Algorithm 1.
//!
//! ```text
//! while a face has q below the threshold and the budget is not spent:
//!     P  = a patch over `rings` rings around it               // the run's PatchStrategy
//!     uv = parameterize P (certified bijective); M2 = Eq. 4    // the run's Parameterizer
//!     vertex position and connectivity updates in the plane    // Eq. 5-6, improve::eq5
//!     map back, certify and replace P                          // as a patch of Algorithm 1
//! ```
//!
//! It reuses Algorithm 1's patch step with the run's strategy and parameterizer
//! ([`ImproveRun::patch_pass`]): a pass marks the faces at or above the threshold as
//! processed, so the strategy seeds only at bad faces and its ring expansion
//! ([`crate::patches::PatchStrategy::widened`]) takes their neighbourhood; the planar stage is
//! [`Eq5Updates`], which keeps the patch's vertices and boundary (the run's planar remesher
//! would remesh the patch instead of improving it); the patch's boundary chains are not
//! resampled. Every replaced patch is certified as in Algorithm 1.
//! Termination: within a pass every patch marks at least one unprocessed face processed
//! (Algorithm 1's argument); a further pass runs only when the previous one strictly lowered
//! the count of faces below the threshold or raised the mesh's smallest angle, and there are
//! at most `passes` of them. Each pass takes one ring more around the bad faces than the last.

use super::{Eq5Options, Eq5Updates, ImproveRun, Improver, ImproverCounts};
use super::{LoopStages, RunError};
use crate::option_error::OptionError;
use crate::quality::TriangleQuality;
use serde::Serialize;

/// Options of Algorithm 2 (Sec. 3.4), with their defaults.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ImproveOptions {
    /// A face whose metric quality q is below this is improved (default 0.5).
    pub q_threshold: f64,
    /// So is a face whose smallest angle in the metric is below this many degrees (default
    /// 30; paper-notes.md Sec. 3.4: selecting by q alone takes many faces that are merely
    /// stretched, at several times the cost).
    pub angle_threshold: f64,
    /// Passes over the faces below the threshold (default 3); a pass runs only while the
    /// previous one strictly lowered their count or raised the smallest angle.
    pub passes: usize,
    /// Rings of faces around a bad face that its patch takes in the first pass, one more in
    /// each further pass (default 2).
    pub rings: usize,
    /// At most this many patches over all passes (default: no bound beyond the passes).
    pub max_patches: Option<usize>,
    /// What a patch's candidate must not lower (default [`Bottom::QualityAndAngles`]).
    pub bottom: Bottom,
    /// The planar updates (Eq. 5-6); their defaults, but 12 halvings of the line search
    /// (30 cost 20 % more for the same result on the shared meshes).
    pub planar: Eq5Options,
}

impl Default for ImproveOptions {
    fn default() -> Self {
        ImproveOptions {
            q_threshold: 0.5,
            angle_threshold: 30.0,
            passes: 3,
            rings: 2,
            max_patches: None,
            bottom: Bottom::QualityAndAngles,
            planar: Eq5Options {
                line_search: 12,
                ..Eq5Options::default()
            },
        }
    }
}

impl ImproveOptions {
    /// Errors for values no run can use, naming the option.
    pub fn validate(&self) -> Result<(), OptionError> {
        let out_of_range = |option, value, range| OptionError::OutOfRange {
            option,
            value,
            range,
        };
        let q = self.q_threshold;
        if !(q.is_finite() && q > 0.0 && q <= 1.0) {
            return Err(out_of_range("improvement threshold", q, "in (0, 1]"));
        }
        let a = self.angle_threshold;
        if !(a.is_finite() && (0.0..60.0).contains(&a)) {
            let range = "in [0°, 60°)";
            return Err(out_of_range("improvement angle threshold", a, range));
        }
        let w = self.planar.w;
        if !(w.is_finite() && w > 0.0) {
            return Err(out_of_range("Eq. 5 weight w", w, "a positive number"));
        }
        if self.rings == 0 {
            return Err(OptionError::TooFew {
                option: "improvement rings",
                value: 0,
                min: 1,
            });
        }
        Ok(())
    }
}

/// What Algorithm 2's acceptance test keeps from falling, besides ranking the candidate's
/// smallest angles leximin against the faces it replaces.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Bottom {
    /// Neither the smallest metric quality q nor the smallest angle (registry name
    /// `q-angles`).
    QualityAndAngles,
    /// The smallest angle only: a candidate that opens a small angle by making another face
    /// more obtuse, and so lowers q_min, is taken (`angles`).
    Angles,
}

impl ImproveOptions {
    /// The face is to be improved: q or its smallest angle below its threshold.
    pub fn is_bad(&self, t: &crate::quality::TriangleQuality) -> bool {
        t.q < self.q_threshold || t.min_angle() < self.angle_threshold
    }
}

/// Algorithm 2 as an [`Improver`] (row `eq5`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Algorithm2 {
    /// Options.
    pub options: ImproveOptions,
}

impl Improver for Algorithm2 {
    fn name(&self) -> &'static str {
        "eq5"
    }

    fn validate(&self) -> Result<(), OptionError> {
        self.options.validate()
    }

    fn improve(
        &self,
        stages: LoopStages<'_>,
        run: &mut dyn ImproveRun,
        rng: &mut crate::Rng,
    ) -> Result<ImproverCounts, RunError> {
        let o = &self.options;
        let planar = Eq5Updates {
            options: o.planar.clone(),
        };
        let mut counts = ImproverCounts::default();
        let mut before: Option<Progress> = None;
        while counts.passes < o.passes {
            let qualities = run.face_qualities();
            let bad: Vec<bool> = qualities.iter().map(|t| o.is_bad(t)).collect();
            let now = Progress::of(&qualities, &bad);
            if now.bad == 0 || before.is_some_and(|b| !now.beats(&b)) {
                break;
            }
            before = Some(now);
            // Each pass reaches one ring farther: the faces still bad after a pass are those
            // whose patch was too small to move their vertices (they sat on its boundary).
            let widened = stages.patches.widened(o.rings + counts.passes);
            let pass_stages = LoopStages {
                patches: widened.as_deref().unwrap_or(stages.patches),
                parameterizer: stages.parameterizer,
                remesher: &planar,
            };
            counts.passes += 1;
            let budget = o.max_patches.map(|m| m.saturating_sub(counts.patches));
            let pass = run.patch_pass(
                pass_stages,
                &bad,
                budget,
                &|old, new| better_at_the_bottom(o.bottom, old, new),
                rng,
            )?;
            counts.patches += pass.patches;
            counts.rejected += pass.rejected;
            if pass.budget_exhausted {
                counts.budget_exhausted = true;
                break;
            }
        }
        Ok(counts)
    }
}

/// Where a pass of Algorithm 2 left the mesh: the faces still to improve, and the smallest
/// angle.
#[derive(Clone, Copy, Debug)]
struct Progress {
    bad: usize,
    theta_min: f64,
}

impl Progress {
    fn of(qualities: &[TriangleQuality], bad: &[bool]) -> Progress {
        Progress {
            bad: bad.iter().filter(|b| **b).count(),
            theta_min: qualities
                .iter()
                .map(|t| t.min_angle())
                .fold(f64::INFINITY, f64::min),
        }
    }

    /// Fewer faces to improve, or a larger smallest angle: a pass that opens the worst face
    /// may leave as many faces under the thresholds (it trades one for another elsewhere in
    /// the patch), and the next pass, one ring wider, still has work.
    fn beats(&self, before: &Progress) -> bool {
        self.bad < before.bad || self.theta_min > before.theta_min
    }
}

/// The candidate is better at the bottom than the faces it replaces: neither its smallest
/// metric quality nor its smallest angle is lower (so no patch lowers the mesh's q_min or
/// θ_min), and its smallest angles, sorted, are lexicographically higher (leximin: the first
/// angle that differs is larger). The mean quality may fall: requiring it not to cost θ_min
/// 3–6° on cow, decimated-knight, fertility and homer for q_avg changes below 0.001
/// (paper-notes.md Sec. 3.4). Testing only
/// the smallest angle refused every patch whose worst face sits on its boundary, which the
/// planar updates cannot move, however much they raised the rest (86 % of the patches on
/// cylinder-axial30). The planar updates lower the energy in the plane; lifted across a
/// crease or a strongly curved part a move can still make a worse triangle on the surface,
/// which is refused.
fn better_at_the_bottom(bottom: Bottom, old: &[TriangleQuality], new: &[TriangleQuality]) -> bool {
    let q_min = |ts: &[TriangleQuality]| ts.iter().map(|t| t.q).fold(f64::INFINITY, f64::min);
    let angles = |ts: &[TriangleQuality]| {
        let mut a: Vec<f64> = ts.iter().map(|t| t.min_angle()).collect();
        a.sort_by(f64::total_cmp);
        a
    };
    let (a_old, a_new) = (angles(old), angles(new));
    // Fewer faces (the planar updates' edge collapses) or more (their splits).
    let q_guard = bottom == Bottom::QualityAndAngles;
    if new.is_empty() || (q_guard && q_min(new) < q_min(old)) || a_new[0] < a_old[0] {
        return false;
    }
    a_new
        .iter()
        .zip(&a_old)
        .find(|(n, o)| n != o)
        .is_some_and(|(n, o)| n > o)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_no_run_can_use_are_named() {
        let bad = |f: fn(&mut ImproveOptions)| {
            let mut o = ImproveOptions::default();
            f(&mut o);
            match o.validate().expect_err("refused") {
                OptionError::OutOfRange { option, .. } | OptionError::TooFew { option, .. } => {
                    option
                }
                other => panic!("{other}"),
            }
        };
        assert_eq!(bad(|i| i.q_threshold = 0.0), "improvement threshold");
        assert_eq!(bad(|i| i.q_threshold = f64::NAN), "improvement threshold");
        assert_eq!(bad(|i| i.q_threshold = 1.5), "improvement threshold");
        assert_eq!(bad(|i| i.planar.w = -1.0), "Eq. 5 weight w");
        assert_eq!(bad(|i| i.planar.w = f64::INFINITY), "Eq. 5 weight w");
        assert_eq!(bad(|i| i.rings = 0), "improvement rings");
        assert!(ImproveOptions::default().validate().is_ok());
    }

    #[test]
    fn the_acceptance_test_is_leximin_on_angles_and_never_lowers_the_bottom() {
        // Triangles with given smallest angle (the other two split the rest) and q.
        let t = |a: f64, q: f64| TriangleQuality {
            q,
            angles: [a, 0.5 * (180.0 - a), 0.5 * (180.0 - a)],
        };
        let old = [t(10.0, 0.3), t(20.0, 0.5), t(40.0, 0.9)];
        // The worst face unchanged (on the patch boundary), the next one raised: accepted.
        assert!(better_at_the_bottom(
            Bottom::QualityAndAngles,
            &old,
            &[t(10.0, 0.3), t(30.0, 0.7), t(40.0, 0.9)]
        ));
        // The bottom raised.
        assert!(better_at_the_bottom(
            Bottom::QualityAndAngles,
            &old,
            &[t(12.0, 0.3), t(15.0, 0.5), t(40.0, 0.9)]
        ));
        // Identical: refused (nothing gained).
        assert!(!better_at_the_bottom(Bottom::QualityAndAngles, &old, &old));
        // The smallest angle falls, or q_min falls, though the rest rises: refused.
        assert!(!better_at_the_bottom(
            Bottom::QualityAndAngles,
            &old,
            &[t(9.0, 0.4), t(50.0, 0.9), t(50.0, 0.9)]
        ));
        assert!(!better_at_the_bottom(
            Bottom::QualityAndAngles,
            &old,
            &[t(10.0, 0.2), t(50.0, 0.9), t(50.0, 0.9)]
        ));
        // The second angle falls while the third rises: refused (leximin, not the sum).
        assert!(!better_at_the_bottom(
            Bottom::QualityAndAngles,
            &old,
            &[t(10.0, 0.3), t(19.0, 0.5), t(60.0, 1.0)]
        ));
        assert!(!better_at_the_bottom(Bottom::QualityAndAngles, &old, &[]));
    }

    #[test]
    fn a_further_pass_runs_after_one_that_lowered_the_count_or_raised_the_smallest_angle() {
        let p = |bad, theta_min| Progress { bad, theta_min };
        let before = p(10, 12.0);
        assert!(p(9, 12.0).beats(&before));
        assert!(
            p(10, 12.5).beats(&before),
            "the worst face opened, as many left"
        );
        assert!(
            p(11, 12.5).beats(&before),
            "one face traded for several, all better"
        );
        assert!(
            !p(10, 12.0).beats(&before),
            "nothing gained: the passes stop"
        );
        assert!(!p(12, 11.0).beats(&before));
    }

    #[test]
    fn with_the_angles_bottom_a_candidate_may_lower_q_min_to_open_the_smallest_angle() {
        let t = |a: f64, q: f64| TriangleQuality {
            q,
            angles: [a, 0.5 * (180.0 - a), 0.5 * (180.0 - a)],
        };
        let old = [t(10.0, 0.3), t(40.0, 0.9)];
        // The sliver opened to 20°, the other face made obtuse below the old q_min.
        let new = [t(20.0, 0.5), t(25.0, 0.25)];
        assert!(!better_at_the_bottom(Bottom::QualityAndAngles, &old, &new));
        assert!(better_at_the_bottom(Bottom::Angles, &old, &new));
        // Neither takes a candidate that lowers the smallest angle.
        let lower = [t(9.0, 0.9), t(60.0, 1.0)];
        assert!(!better_at_the_bottom(Bottom::Angles, &old, &lower));
    }
}
