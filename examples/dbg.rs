use ehl_petsc::reynolds::element::*;
fn main() {
    let visc = ehl_petsc::physics::rheology::ViscosityLaw::roelands(0.012, 23e-9, 1.96e8, None).unwrap();
    let dens = ehl_petsc::physics::rheology::DensityLaw::DowsonHigginson { rho_r: 870.0 };
    let ph = 8.45220e8; let eta_r = 0.012;
    let eta = move |p: f64| { let (e, de) = visc.viscosity_and_derivative(p * ph); (e / eta_r, de * ph / eta_r) };
    let rho = move |p: f64| { let (r, dr) = dens.ratio_and_derivative(p * ph); (r, dr * ph) };
    let d2eta = move |p: f64| visc.viscosity_second_derivative(p * ph) * ph * ph / eta_r;
    let d2rho = move |p: f64| dens.ratio_second_derivative(p * ph) * ph * ph;
    let fluid = Fluid { eta: &eta, rho: &rho, d2eta: &d2eta, d2rho: &d2rho, lambda_bar: 2.7958e-3 };
    let verts = [[0.0, 0.0], [-1.0, 0.0], [-1.0, -1.0]];
    let p = [1.0, 0.0, 0.0, 0.8660254037844386, 0.0, 0.7071067811865476];
    let h = [0.11614503148574151, 0.08288987225495381, 0.38035512234187874, 0.02690854320338698, 0.12916718462690158, 0.018543570120987618];
    let vel = [[1.0, 0.0]; 3];
    for supg in [false, true] {
        let out = reynolds_element(&verts, &p, &h, &vel, &fluid, &Stabilisation { supg, delta: 1.0 });
        println!("supg {supg}: r = {:?}", out.r);
    }
    for pp in [0.0, 0.5, 1.0] { println!("eta({pp}) = {:?} d2 {}", eta(pp), d2eta(pp)); }
}
