//! The scene as a dimensionless problem: the lubricant laws, lambda_bar, the entrainment
//! velocity field, the cavitation penalty and the Reynolds element's stabilisation, in the
//! units of the Hertz contact (X = x/a, P = p/p_H, H = h R/a^2).
use crate::case::Scene;
use crate::ehl::system::{EhlParams, Lubricant};
use crate::solid::assembly;

/// Dimensionless lubricant laws of the scene.
pub fn lubricant(scene: &Scene) -> Lubricant {
    let ph = scene.hertz().ph;
    let visc = scene.viscosity_law().expect("lubricated scene");
    let dens = scene.density_law().expect("lubricated scene");
    let eta_r = visc.reference_viscosity();
    Lubricant {
        eta: Box::new(move |p: f64| {
            let (e, de) = visc.viscosity_and_derivative(p * ph);
            (e / eta_r, de * ph / eta_r)
        }),
        rho: Box::new(move |p: f64| {
            let (r, dr) = dens.ratio_and_derivative(p * ph);
            (r, dr * ph)
        }),
        d2eta: Box::new(move |p: f64| visc.viscosity_second_derivative(p * ph) * ph * ph / eta_r),
        d2rho: Box::new(move |p: f64| dens.ratio_second_derivative(p * ph) * ph * ph),
    }
}

/// lambda_bar = 12 eta_R Ue R^2 / (a^3 p_H).
pub fn lambda_bar(scene: &Scene) -> f64 {
    let h = scene.hertz();
    let eta_r = scene.lubricant.as_ref().expect("lubricated scene").viscosity;
    let ue = scene.operating.entrainment_speed.expect("lubricated scene");
    let r = scene.geometry.ball_radius;
    12.0 * eta_r * ue * r * r / (h.a.powi(3) * h.ph)
}

/// The scene's dimensionless entrainment velocity (Um, Wm)/Ue as a function of (X, Z).
pub fn velocity_field(scene: &Scene) -> Box<dyn Fn(f64, f64) -> [f64; 2] + Send + Sync> {
    let kin = scene.kinematics().expect("lubricated scene");
    let (a, ue) = (scene.scales().a, scene.operating.entrainment_speed.unwrap());
    Box::new(move |x: f64, z: f64| [kin.um(x * a, z * a) / ue, kin.wm(x * a, z * a) / ue])
}

/// The scene's cavitation penalty xi (0 without the penalty model). The complementarity
/// form has none: its partner of P is the Reynolds residual itself (at a penalty solution
/// that residual is the penalty's force where the film cavitates, and Newton sets P = 0
/// there; with the penalty kept, it is zero and Newton's first step went astray).
pub(super) fn penalty(scene: &Scene) -> f64 {
    if scene.effects.cavitation == crate::case::CavitationModel::Penalty {
        scene.reynolds.penalty
    } else {
        0.0
    }
}

/// Whether the scene's cavitation condition is the complementarity form.
pub(super) fn complementarity(scene: &Scene) -> bool {
    scene.effects.cavitation == crate::case::CavitationModel::Complementarity
}

/// EHL parameters of the scene (dimensionless).
pub(super) fn ehl_params(scene: &Scene, nu: f64, half: bool) -> EhlParams {
    let penalty = penalty(scene);
    EhlParams {
        lambda_bar: lambda_bar(scene),
        traction: assembly::traction_factor(nu),
        load: if half { std::f64::consts::PI / 3.0 } else { 2.0 * std::f64::consts::PI / 3.0 },
        penalty,
        stabilisation: stabilisation(scene, penalty),
        velocity: velocity_field(scene),
        nu,
    }
}

/// The Reynolds element's stabilisation for the scene's `reynolds.stabilisation`, with the
/// cavitation penalty `penalty` in its strong residual.
pub fn stabilisation(scene: &Scene, penalty: f64) -> crate::reynolds::element::Stabilisation {
    use crate::case::Stabilisation as S;
    use crate::reynolds::element::{Stabilisation, StrongResidual};
    let choice = scene.reynolds.stabilisation;
    Stabilisation {
        supg: choice != S::Off,
        delta: crate::ehl_options::get().supg_delta,
        id: scene.reynolds.artificial_diffusion,
        cd: scene.reynolds.crosswind_diffusion,
        jump: scene.reynolds.gradient_jump,
        penalty,
        // Every lubricant law gets the same consistent residual; an incompressible one
        // takes its Peclet number from the elastic film response (see `supg_tau`).
        residual: match choice {
            S::SupgExact => StrongResidual::Full,
            S::SupgCouette => StrongResidual::Couette,
            _ => StrongResidual::FrozenLubricant,
        },
        film_peclet: true,
        complementarity: complementarity(scene),
    }
}

/// Estimated dimensionless central film ([`Scene::film_estimate`]), at least 0.02. With
/// Hamrock-Dowson's piezoviscous fit alone, a steel ball on PDMS (M = 31, L = 2e-4)
/// started from 65 nm, where its film is 7 um, and Newton stalled from every start.
pub(super) fn hc_guess(scene: &Scene) -> f64 {
    (scene.film_estimate().unwrap_or(0.0) / scene.scales().film_scale()).max(0.02)
}
