//! The continuations' homotopies: the scene parameters a continuation varies ([`Parameter`]:
//! at t = 1 the scene, at smaller t a milder problem), the order they are tried in
//! ([`homotopies`]), and how a ramp steps t back to 1 ([`RampSteps`]). No solve here: the
//! solves are [`super::newton`]'s, the path that orders them [`super::continuation`]'s.
use super::problem::hc_guess;
use super::start::RampLimits;
use crate::case::Scene;

/// A scene parameter a continuation varies, with the scene's value: at t = 1 the scene
/// itself, at smaller t a milder problem.
#[derive(Clone, Copy, Debug)]
pub(super) enum Parameter {
    /// The tilt angle lambda (deg) becomes min(lambda / t, 90): weaker spin.
    Tilt(f64),
    /// The pressure-viscosity coefficient alpha (1/Pa) and the Roelands exponent z are
    /// scaled by t: a less steep viscosity at the same Hertz geometry.
    PressureViscosity { alpha: f64, z: Option<f64> },
    /// The load (N) is scaled by t: smaller M and alpha p_H.
    Load(f64),
    /// The entrainment speed (m/s) becomes Ue / t: a thicker film.
    Speed(f64),
    /// The cavitation penalty xi is scaled by t.
    Penalty(f64),
}

impl Parameter {
    pub(super) fn name(self) -> &'static str {
        match self {
            Parameter::Tilt(_) => "tilt",
            Parameter::PressureViscosity { .. } => "pressure-viscosity",
            Parameter::Load(_) => "load",
            Parameter::Speed(_) => "speed",
            Parameter::Penalty(_) => "penalty",
        }
    }

    /// Sets the parameter of `sc` at t.
    pub(super) fn apply(self, sc: &mut Scene, t: f64) {
        match self {
            Parameter::Tilt(tilt) => sc.operating.tilt_angle = (tilt / t).min(90.0),
            Parameter::PressureViscosity { alpha, z } => {
                if let Some(l) = sc.lubricant.as_mut() {
                    l.pressure_viscosity = l.pressure_viscosity.map(|_| alpha * t);
                    l.roelands_exponent = z.map(|z| z * t);
                }
            }
            Parameter::Load(load) => sc.operating.load = load * t,
            Parameter::Speed(ue) => sc.operating.entrainment_speed = Some(ue / t),
            Parameter::Penalty(xi) => sc.reynolds.penalty = xi * t,
        }
    }

    /// The parameter's value at t, for the log.
    pub(super) fn show(self, t: f64) -> String {
        match self {
            Parameter::Tilt(tilt) => format!("lambda = {:.4} deg", (tilt / t).min(90.0)),
            Parameter::PressureViscosity { alpha, .. } => format!("alpha = {:.4} GPa^-1", alpha * t * 1e9),
            Parameter::Load(load) => format!("L = {:.4} N", load * t),
            Parameter::Speed(ue) => format!("Ue = {:.4} m/s", ue / t),
            Parameter::Penalty(xi) => format!("xi = {:.4e}", xi * t),
        }
    }

    /// Load and speed: continuations that change the film's whole shape, tried after the
    /// ones nearest the scene (tilt, pressure-viscosity) failed. Their search from a
    /// coarser level's pressure has not converged on any level measured (M = 100, L = 20 at
    /// 0.0625 a and 0.03125 a: L/8 to L/64 and 2 Ue to 32 Ue all fail, 210 s, measured
    /// before a milder problem's start had its own film, [`film_gain`]).
    pub(super) fn last_resort(self) -> bool {
        matches!(self, Parameter::Load(_) | Parameter::Speed(_))
    }

    /// The parameter changes the entrainment velocity field.
    pub(super) fn kinematic(self) -> bool {
        matches!(self, Parameter::Tilt(_))
    }

    /// The parameter changes the film in the units of its own Hertz contact (X = x/a,
    /// H = h R/a^2): a lighter load has a smaller a, so the same film is a thicker H; a
    /// faster speed has a thicker film. The dimensionless Hertz pressure and its deflection
    /// are the same at every load, so only H0 of a start is wrong for another value.
    pub(super) fn moves_film(self) -> bool {
        matches!(self, Parameter::Load(_) | Parameter::Speed(_))
    }

    /// A smaller t gives a thinner film (pressure-viscosity: hc grows about as alpha^0.5),
    /// so once a try ends with the film closed, the smaller t that follow would close it too.
    pub(super) fn thins_film(self) -> bool {
        matches!(self, Parameter::PressureViscosity { .. })
    }
}

/// How much a start of `from` at `p = from_t` raises its H0 for a solve at `p = t`: the
/// estimated central film's gain ([`hc_guess`]) where the film at t is the thicker. At L/8
/// the Hertz start's H0, the scene's film, is about a fifth of the milder problem's own.
/// A thinner film is not imposed: a start whose film is too thick only needs the load
/// balance to lower H0, one too thin can close the film at its first step.
pub(super) fn film_gain(from: &Scene, p: Parameter, from_t: f64, t: f64) -> f64 {
    if !p.moves_film() {
        return 0.0;
    }
    let at = |t: f64| {
        let mut sc = from.clone();
        p.apply(&mut sc, t);
        hc_guess(&sc)
    };
    (at(t) - at(from_t)).max(0.0)
}

/// The viscosity rise over the contact, ln(eta(p_H)/eta_R), below which a smaller alpha is
/// not a milder problem from the Hertz start (a factor 1.65 in the viscosity; the
/// isoviscous-elastic points measured had 2e-4 to 0.07).
const MILD_VISCOSITY_RISE: f64 = 0.5;

/// How t moves: the search for a milder problem tries `first`, halving down to `lowest`;
/// the ramp back to t = 1 multiplies t by `ratio` (by its square root after a failure).
#[derive(Clone, Copy, Debug)]
pub(super) struct Ramp {
    pub(super) first: f64,
    pub(super) lowest: f64,
    pub(super) ratio: f64,
}

/// One continuation: a parameter and its ramp.
#[derive(Clone, Copy, Debug)]
pub(super) struct Homotopy {
    pub(super) parameter: Parameter,
    pub(super) ramp: Ramp,
}

/// The continuations tried, in order, when Newton fails from the Hertz start: first (spin
/// kinematics, lambda < 90 deg) the tilt angle, then pressure-viscosity (alpha > 0), then
/// load, then speed. Pressure-viscosity goes before load: on the hard suite it is the one
/// that converges (alpha30 on the paper mesh: load continuation fails from every Hertz
/// start down to L/64, alpha/2 -> alpha converges in 23 + 8 iterations).
///
/// From the Hertz start (`from_hertz`) the pressure-viscosity continuation is left out where
/// the viscosity barely rises over the contact (ln(eta(p_H)/eta_R) below
/// [`MILD_VISCOSITY_RISE`]): a smaller alpha is then the same problem, and it failed as
/// plain Newton did on every isoviscous-elastic point measured (a steel ball on PDMS, the
/// Moes points at L = 0.01 from M = 10 to 1000; at M = 1000 its three tries took 180 s of a
/// retry at 83,937 unknowns). From a coarser level's pressure it stays: there its first
/// step, solved with the bt line search, is what converges (docs/practice.md, "Soft EHL").
pub(super) fn homotopies(scene: &Scene, from_hertz: bool) -> Vec<Homotopy> {
    let alpha = scene.lubricant.as_ref().and_then(|l| l.pressure_viscosity).unwrap_or(0.0);
    let mild = from_hertz && scene.viscosity_rise().unwrap_or(0.0) < MILD_VISCOSITY_RISE;
    let alpha = if mild { 0.0 } else { alpha };
    let z = scene.lubricant.as_ref().and_then(|l| l.roelands_exponent);
    let ue = scene.operating.entrainment_speed.unwrap_or(0.0);
    let tilt = scene.operating.tilt_angle;
    // A small tilt angle (strong spin) is milder at a larger one; only with spin kinematics.
    let spin = scene.effects.kinematics == crate::case::KinematicsModel::Spin && tilt < 90.0;
    let halving = |first: f64, lowest: f64| Ramp { first, lowest, ratio: 2.0 };
    let mut list = Vec::new();
    if spin {
        list.push(Homotopy { parameter: Parameter::Tilt(tilt), ramp: halving(0.5, 1.0 / 64.0) });
    }
    if alpha > 0.0 {
        list.push(Homotopy { parameter: Parameter::PressureViscosity { alpha, z }, ramp: halving(0.5, 0.125) });
    }
    list.push(Homotopy { parameter: Parameter::Load(scene.operating.load), ramp: halving(1.0 / 8.0, 1.0 / 64.0) });
    list.push(Homotopy { parameter: Parameter::Speed(ue), ramp: halving(0.25, 1.0 / 64.0) });
    list
}

/// The steps of a continuation's ramp towards t = 1: t times the ratio (the last step cut
/// at t = 1), or a value of the schedule (where a coarser level's ramp converged) between
/// t and that.
pub(super) struct RampSteps<'s> {
    ratio: f64,
    schedule: &'s [f64],
    /// The failed steps left before the ramp gives up (None: no such limit).
    pub(super) failures_left: Option<usize>,
    /// A ramp gives up when a failed step would be followed by a ratio below this.
    smallest_ratio: f64,
}

impl<'s> RampSteps<'s> {
    /// Steps by `ratio` through `schedule`, within `limits`.
    pub(super) fn new(ratio: f64, schedule: &'s [f64], limits: RampLimits) -> RampSteps<'s> {
        RampSteps { ratio, schedule, failures_left: limits.failures, smallest_ratio: limits.smallest_ratio }
    }

    /// The value to try from t, and whether it is a value of the schedule.
    pub(super) fn next(&self, t: f64) -> (f64, bool) {
        // Within round-off of the end is the end (heavy-3gpa's load ramp by factors of
        // 2^(1/4) ended at t = 1 - 1e-16, then solved t = 1 again in 0 iterations).
        let next = if t * self.ratio > 1.0 - 1e-9 { 1.0 } else { t * self.ratio };
        match self.schedule.iter().copied().find(|&s| s > t * (1.0 + 1e-9)).filter(|&s| s < next) {
            Some(s) => (s, true),
            None => (next, false),
        }
    }

    /// After the step from t to `tried` failed: the ratio becomes the square root of the
    /// step tried (a step cut at t = 1 is halved in log t from its own size, so the same
    /// failing solve is not repeated: from a scheduled alpha/1.41 with the ratio still 2,
    /// the step to alpha failed, and the square root of 2 gave alpha again). A failed
    /// scheduled step drops the schedule, and the ramp goes on by its own ratio from there;
    /// such a step may be below the smallest ratio once (the coarser level's path had small
    /// steps). Returns false when the ramp gives up: its ratio too small, or its failures
    /// spent.
    pub(super) fn failed(&mut self, t: f64, tried: f64, planned: bool) -> bool {
        self.ratio = (tried / t).sqrt();
        if let Some(left) = self.failures_left.as_mut() {
            *left = left.saturating_sub(1);
            if *left == 0 {
                return false;
            }
        }
        if planned {
            self.schedule = &[];
            true
        } else {
            self.ratio >= self.smallest_ratio
        }
    }
}
#[cfg(test)]
mod tests {
    use super::{homotopies, Parameter, RampLimits, RampSteps};

    /// The values a ramp from t0 tries when a step from t to t' converges iff `ok(t, t')`.
    fn tried(t0: f64, ratio: f64, schedule: &[f64], ok: impl Fn(f64, f64) -> bool) -> (bool, Vec<f64>) {
        tried_with(t0, ratio, schedule, RampLimits::DEFAULT, ok)
    }

    /// The same, with the ramp's `limits`.
    fn tried_with(t0: f64, ratio: f64, schedule: &[f64], limits: RampLimits, ok: impl Fn(f64, f64) -> bool) -> (bool, Vec<f64>) {
        let (mut steps, mut t, mut out) = (RampSteps::new(ratio, schedule, limits), t0, Vec::new());
        while t < 1.0 {
            let (next, planned) = steps.next(t);
            out.push(next);
            if ok(t, next) {
                t = next;
            } else if !steps.failed(t, next, planned) {
                return (false, out);
            }
        }
        (true, out)
    }

    #[test]
    fn a_ramp_halves_a_failed_step_and_never_repeats_it() {
        let close = |a: &[f64], b: &[f64]| a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12);
        let (r2, r4) = (2f64.sqrt(), 2f64.powf(0.25));
        // By factors of 2 from 1/2, converging only by steps up to 1.3: 1 fails, 1/sqrt(2)
        // fails, then steps of 2^(1/4) reach 1.
        let (done, t) = tried(0.5, 2.0, &[], |t, n| n / t <= 1.3);
        assert!(done && close(&t, &[1.0, 0.5 * r2, 0.5 * r4, 0.5 * r2, 0.5 * r2 * r4, 1.0]), "{t:?}");
        // A problem that converges only up to t = 0.9, from the scheduled 1/sqrt(2) with the
        // ratio still 2: the step to 1 is cut to sqrt(2) and fails; the next try is
        // 2^(1/4) from there, not 1 again.
        let (done, t) = tried(0.5, 2.0, &[0.5f64.sqrt()], |_, n| n <= 0.9);
        assert!(!done && close(&t, &[0.5 * r2, 1.0, 0.5 * r2 * r4, 1.0, 0.5 * r2 * r4 * 2f64.powf(0.125)]), "{t:?}");
        assert!(t.windows(2).all(|w| w[0] != w[1]), "a failed step was tried again: {t:?}");
        // A step cut at t = 1 whose square root is below the smallest ratio: no retry.
        assert_eq!(tried(0.96, 2.0, &[], |_, _| false), (false, vec![1.0]));
        // Steps of 2, 2^(1/2), 2^(1/4), 2^(1/8) and then the ramp gives up.
        let (done, t) = tried(0.5, 2.0, &[], |_, _| false);
        assert!(!done && t.len() == 4, "{t:?}");
    }

    #[test]
    fn a_ramp_with_a_failure_limit_gives_up_at_it() {
        let r2 = 2f64.sqrt();
        // Converging only by steps up to 1.3 from 1/2: the second failure ends the ramp.
        let (done, t) = tried_with(0.5, 2.0, &[], RampLimits::BEFORE_A_REMEDY, |t, n| n / t <= 1.3);
        assert!(!done && t.len() == 2 && (t[1] - 0.5 * r2).abs() < 1e-12, "{t:?}");
        // Failures between converged steps count too: 1 fails, 1/sqrt(2) converges, 1 fails.
        let (done, t) = tried_with(0.5, 2.0, &[], RampLimits::BEFORE_A_REMEDY, |_, n| n < 0.8);
        assert!(!done && t == vec![1.0, 0.5 * r2, 1.0], "{t:?}");
        // One failure and then convergence: the limit does not bind.
        assert_eq!(tried_with(0.5, 2.0, &[], RampLimits::BEFORE_A_REMEDY, |t, n| n / t <= 1.5), (true, vec![1.0, 0.5 * r2, 1.0]));
        // Without the limit the same ramp as before.
        assert_eq!(tried_with(0.5, 2.0, &[], RampLimits::DEFAULT, |t, n| n / t <= 1.3), tried(0.5, 2.0, &[], |t, n| n / t <= 1.3));
    }

    #[test]
    fn a_patient_ramp_takes_smaller_steps_before_it_gives_up() {
        // M = 20, L = 20 with c_J = 1: from alpha 62.59 of 68.25 GPa^-1 the step to alpha
        // fails and only a step of at most 1.05 converges.
        let (t0, r) = (62.59 / 68.25, (68.25f64 / 62.59).sqrt());
        let ok = |t: f64, n: f64| n / t <= 1.05;
        assert_eq!(tried_with(t0, 2.0, &[], RampLimits::DEFAULT, ok), (false, vec![1.0]));
        let (done, t) = tried_with(t0, 2.0, &[], RampLimits::PATIENT, ok);
        assert!(done && t.len() == 3 && (t[1] - t0 * r).abs() < 1e-12, "{t:?}");
    }

    /// A milder load's start gets its own film: Hamrock-Dowson's hc goes as W^-0.067 and
    /// the Hertz radius a as W^(1/3), so the dimensionless film H = h R/a^2 of L/8 is
    /// 8^(2/3 + 0.067) = 4.6 times the scene's. The pressure-viscosity continuation keeps
    /// its start, and no step thins a start's film.
    #[test]
    fn a_lighter_load_starts_from_its_own_thicker_film() {
        use super::{film_gain, hc_guess};
        let scene = crate::case::parse_scene(include_str!("../../../cases/paper/table2-ue2.toml"), "table2-ue2").unwrap();
        let load = Parameter::Load(scene.operating.load);
        let h = hc_guess(&scene);
        let ratio = 1.0 + film_gain(&scene, load, 1.0, 0.125) / h;
        assert!((ratio / 8f64.powf(2.0 / 3.0 + 0.067) - 1.0).abs() < 1e-3, "{ratio}");
        let (g, g8, g4) = (film_gain(&scene, load, 0.25, 0.125), film_gain(&scene, load, 1.0, 0.125), film_gain(&scene, load, 1.0, 0.25));
        assert!((g - (g8 - g4)).abs() < 1e-12 * g8, "{g} against {}", g8 - g4);
        // A heavier load or a slower speed: the start keeps its thicker film.
        assert_eq!(film_gain(&scene, load, 0.125, 1.0), 0.0);
        let ue = scene.operating.entrainment_speed.unwrap();
        assert_eq!(film_gain(&scene, Parameter::Speed(ue), 0.25, 1.0), 0.0);
        // Four times the speed: hc as Ue^0.67 at the same a.
        let ratio = 1.0 + film_gain(&scene, Parameter::Speed(ue), 1.0, 0.25) / h;
        assert!((ratio / 4f64.powf(0.67) - 1.0).abs() < 1e-3, "{ratio}");
        let pv = Parameter::PressureViscosity { alpha: 2e-8, z: None };
        assert_eq!(film_gain(&scene, pv, 1.0, 0.5), 0.0);
    }

    #[test]
    fn the_homotopies_reach_the_scene_at_t_equal_1_and_are_milder_below() {
        let scene = crate::case::parse_scene(include_str!("../../../cases/paper/table2-ue2.toml"), "table2-ue2").unwrap();
        let list = homotopies(&scene, true);
        let names: Vec<&str> = list.iter().map(|h| h.parameter.name()).collect();
        // Table 2 has alpha > 0 and rolls without spin: no tilt continuation.
        assert_eq!(names, ["pressure-viscosity", "load", "speed"]);
        // Barus with alpha 400 times smaller: the viscosity rises by e^0.05 over the
        // contact. From the Hertz start a smaller alpha is no milder problem, from a coarser
        // level's pressure the continuation stays.
        let mut iso = scene.clone();
        iso.effects.viscosity = crate::case::ViscosityModel::Barus;
        iso.lubricant.as_mut().unwrap().pressure_viscosity = Some(23e-9 / 400.0);
        let names = |from_hertz| homotopies(&iso, from_hertz).iter().map(|h| h.parameter.name()).collect::<Vec<_>>();
        assert_eq!(names(true), ["load", "speed"]);
        assert_eq!(names(false), ["pressure-viscosity", "load", "speed"]);
        // Without the last resorts only the continuations nearest the scene remain.
        let last: Vec<bool> = list.iter().map(|h| h.parameter.last_resort()).collect();
        assert_eq!(last, [false, true, true]);
        assert!(!Parameter::Tilt(0.5).last_resort());
        for h in &list {
            let mut sc = scene.clone();
            h.parameter.apply(&mut sc, 1.0);
            assert_eq!(sc.operating, scene.operating, "{}", h.parameter.name());
            assert_eq!(sc.lubricant, scene.lubricant, "{}", h.parameter.name());
        }
        // At t = 1/2: half the load, twice the speed (a thicker film), half of alpha.
        let mut sc = scene.clone();
        Parameter::Load(scene.operating.load).apply(&mut sc, 0.5);
        Parameter::Speed(scene.operating.entrainment_speed.unwrap()).apply(&mut sc, 0.5);
        assert_eq!(sc.operating.load, 0.5 * scene.operating.load);
        assert_eq!(sc.operating.entrainment_speed, Some(2.0 * scene.operating.entrainment_speed.unwrap()));
    }
}
