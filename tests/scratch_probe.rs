use qrm::measurement::*;
use qrm::geometry::Point;
use qrm::edc;
#[test]
fn probe() {
    let p = [Point::new(11.268649591496413, 11.54081464789538), Point::new(10.949760386396054, 7.977679204220196), Point::new(9.57462546423655, 11.707719600153158)];
    let ang = [0.6845411351737586f64, -1.654402896663238, 3.0315981249627084];
    let u = ang.map(|t| Point::new(t.cos(), t.sin()));
    // camera = A - a u_A = B - b u_B  -> solve 2x2
    let (dx, dy) = (p[0].x - p[1].x, p[0].y - p[1].y);
    // a u_A - b u_B = A - B
    let det = u[0].x * (-u[1].y) - (-u[1].x) * u[0].y;
    let a = (dx * (-u[1].y) - (-u[1].x) * dy) / det;
    let cam = Point::new(p[0].x - a * u[0].x, p[0].y - a * u[0].y);
    let rho = p.map(|q| q.distance(cam));
    println!("camera {cam:?} ranges {rho:?}");
    let r = rho[1] / rho[0]; let s = rho[2] / rho[0];
    println!("r {r} s {s}");
    let a2 = u[0]; let b2 = Point::new(r*u[1].x, r*u[1].y); let c2 = Point::new(s*u[2].x, s*u[2].y);
    println!("class {:?} values {:?}", edc::classify(a2,b2,c2), qrm::geometry::boundary_values(&a2,&b2,&c2));
    println!("{}", sweep_regions(u, &[(0,1),(0,2)], qrm::calculus::RelationSet::all(20)));
}
