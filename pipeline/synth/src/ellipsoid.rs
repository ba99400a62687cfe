//! A lump placed in the world, prepared for analytic ray intersection.

/// An ellipsoid in world coordinates, stored as the map into its unit sphere (translate,
/// turn by −yaw, divide by the radii) so that intersection is one quadratic.
#[derive(Clone, Copy, Debug)]
pub(super) struct Ellipsoid {
    pub center: [f64; 3],
    cos: f64,
    sin: f64,
    inverse_radii: [f64; 3],
    /// Radius of the sphere about `center` that holds the ellipsoid.
    pub bound: f64,
}

impl Ellipsoid {
    pub fn new(center: [f64; 3], radii: [f64; 3], yaw: f64) -> Ellipsoid {
        Ellipsoid {
            center,
            cos: yaw.cos(),
            sin: yaw.sin(),
            inverse_radii: [1.0 / radii[0], 1.0 / radii[1], 1.0 / radii[2]],
            bound: radii[0].max(radii[1]).max(radii[2]),
        }
    }

    /// A world vector in the unit-sphere frame (no translation).
    fn unit_frame(&self, v: [f64; 3]) -> [f64; 3] {
        [
            (self.cos * v[0] + self.sin * v[1]) * self.inverse_radii[0],
            (-self.sin * v[0] + self.cos * v[1]) * self.inverse_radii[1],
            v[2] * self.inverse_radii[2],
        ]
    }

    /// Smallest ray parameter `t > min_t` at which `origin + t·direction` meets the surface.
    pub fn hit(&self, origin: [f64; 3], direction: [f64; 3], min_t: f64) -> Option<f64> {
        let o = self.unit_frame([
            origin[0] - self.center[0],
            origin[1] - self.center[1],
            origin[2] - self.center[2],
        ]);
        let d = self.unit_frame(direction);
        let a = dot(d, d);
        let b = dot(o, d);
        let c = dot(o, o) - 1.0;
        let discriminant = b * b - a * c;
        if discriminant < 0.0 {
            return None;
        }
        let root = discriminant.sqrt();
        let near = (-b - root) / a;
        if near > min_t {
            return Some(near);
        }
        let far = (-b + root) / a;
        (far > min_t).then_some(far)
    }

    /// Outward unit normal at surface point `p`: the gradient of the implicit function, taken
    /// back from the unit-sphere frame.
    pub fn normal(&self, p: [f64; 3]) -> [f64; 3] {
        let u = self.unit_frame([
            p[0] - self.center[0],
            p[1] - self.center[1],
            p[2] - self.center[2],
        ]);
        let g = [
            u[0] * self.inverse_radii[0],
            u[1] * self.inverse_radii[1],
            u[2] * self.inverse_radii[2],
        ];
        normalize([
            self.cos * g[0] - self.sin * g[1],
            self.sin * g[0] + self.cos * g[1],
            g[2],
        ])
    }
}

pub(super) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(super) fn normalize(v: [f64; 3]) -> [f64; 3] {
    let n = dot(v, v).sqrt();
    [v[0] / n, v[1] / n, v[2] / n]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hits_a_turned_ellipsoid_where_its_equation_says() {
        let e = Ellipsoid::new([1.0, 2.0, 0.5], [2.0, 0.5, 1.0], 0.7);
        let origin = [-3.0, 0.0, 1.0];
        let direction = [1.0, 0.5, -0.1];
        let t = e.hit(origin, direction, 0.0).expect("aimed at it");
        let p = [
            origin[0] + t * direction[0],
            origin[1] + t * direction[1],
            origin[2] + t * direction[2],
        ];
        // Independent check: rotate by −yaw by hand and evaluate the ellipsoid equation.
        let (x, y, z) = (p[0] - 1.0, p[1] - 2.0, p[2] - 0.5);
        let (c, s) = (0.7f64.cos(), 0.7f64.sin());
        let (u, v) = (c * x + s * y, -s * x + c * y);
        let f = (u / 2.0).powi(2) + (v / 0.5).powi(2) + z * z;
        assert!((f - 1.0).abs() < 1e-9, "{f}");
        let n = e.normal(p);
        assert!(dot(n, direction) < 0.0, "faces the ray");
        assert!(e.hit(origin, [-1.0, 0.0, 0.0], 0.0).is_none(), "behind");
    }
}
