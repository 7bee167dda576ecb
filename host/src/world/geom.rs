//! Small 3-D vector and rotation helpers for scenes, meshes and the renderer (f64, metres
//! unless a name says otherwise). The vector type is the core's
//! [`tirroi_core::sensor::flux::Vec3`], so positions and normals pass to the core's flux
//! functions without conversion.

pub use tirroi_core::sensor::flux::Vec3;

/// a + b.
pub fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// a − b.
pub fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// s·a.
pub fn scale(a: Vec3, s: f64) -> Vec3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// a · b.
pub fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// a × b.
pub fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// |a|.
pub fn norm(a: Vec3) -> f64 {
    dot(a, a).sqrt()
}

/// a/|a|, or a itself when it is the zero vector.
pub fn normalize(a: Vec3) -> Vec3 {
    let n = norm(a);
    if n > 0.0 { scale(a, 1.0 / n) } else { a }
}

/// A 3×3 rotation matrix, row-major: `apply` computes M·v.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rotation(pub [[f64; 3]; 3]);

impl Rotation {
    /// The identity.
    pub const IDENTITY: Rotation = Rotation([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);

    /// Rotation by `angle_rad` about the unit (or any non-zero) `axis`, right-handed.
    pub fn about_axis(axis: Vec3, angle_rad: f64) -> Rotation {
        let [x, y, z] = normalize(axis);
        let (s, c) = angle_rad.sin_cos();
        let t = 1.0 - c;
        Rotation([
            [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
            [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
            [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
        ])
    }

    /// Rotation from a quaternion [w, x, y, z] (normalised here; the zero quaternion
    /// gives the identity).
    pub fn from_quaternion(q: [f64; 4]) -> Rotation {
        let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
        if n.is_nan() || n <= 0.0 {
            return Rotation::IDENTITY;
        }
        let [w, x, y, z] = [q[0] / n, q[1] / n, q[2] / n, q[3] / n];
        Rotation([
            [
                1.0 - 2.0 * (y * y + z * z),
                2.0 * (x * y - w * z),
                2.0 * (x * z + w * y),
            ],
            [
                2.0 * (x * y + w * z),
                1.0 - 2.0 * (x * x + z * z),
                2.0 * (y * z - w * x),
            ],
            [
                2.0 * (x * z - w * y),
                2.0 * (y * z + w * x),
                1.0 - 2.0 * (x * x + y * y),
            ],
        ])
    }

    /// Rotation from Z-Y-X Euler angles in degrees (yaw about z, then pitch about y,
    /// then roll about x): M = Rz(yaw)·Ry(pitch)·Rx(roll).
    pub fn from_euler_zyx_deg(yaw_deg: f64, pitch_deg: f64, roll_deg: f64) -> Rotation {
        Rotation::about_axis([0.0, 0.0, 1.0], yaw_deg.to_radians())
            .then(&Rotation::about_axis(
                [0.0, 1.0, 0.0],
                pitch_deg.to_radians(),
            ))
            .then(&Rotation::about_axis(
                [1.0, 0.0, 0.0],
                roll_deg.to_radians(),
            ))
    }

    /// The shortest rotation taking direction `from` onto direction `to` (any non-zero
    /// vectors); opposite directions turn by π about an axis perpendicular to `from`.
    pub fn between(from: Vec3, to: Vec3) -> Rotation {
        let a = normalize(from);
        let b = normalize(to);
        let axis = cross(a, b);
        let s = norm(axis);
        let c = dot(a, b);
        if s > 1e-12 {
            return Rotation::about_axis(axis, s.atan2(c));
        }
        if c > 0.0 {
            return Rotation::IDENTITY;
        }
        // Antiparallel: any axis perpendicular to `a`.
        let helper = if a[0].abs() < 0.9 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        Rotation::about_axis(cross(a, helper), std::f64::consts::PI)
    }

    /// M·v.
    pub fn apply(&self, v: Vec3) -> Vec3 {
        let m = &self.0;
        [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
    }

    /// Mᵀ·v (the inverse rotation).
    pub fn apply_inverse(&self, v: Vec3) -> Vec3 {
        let m = &self.0;
        [
            m[0][0] * v[0] + m[1][0] * v[1] + m[2][0] * v[2],
            m[0][1] * v[0] + m[1][1] * v[1] + m[2][1] * v[2],
            m[0][2] * v[0] + m[1][2] * v[1] + m[2][2] * v[2],
        ]
    }

    /// The product self·other (apply `other` first, then `self`).
    pub fn then(&self, other: &Rotation) -> Rotation {
        let a = &self.0;
        let b = &other.0;
        let mut m = [[0.0; 3]; 3];
        for (i, row) in m.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
            }
        }
        Rotation(m)
    }

    /// The inverse (transpose).
    pub fn inverse(&self) -> Rotation {
        let m = &self.0;
        Rotation([
            [m[0][0], m[1][0], m[2][0]],
            [m[0][1], m[1][1], m[2][1]],
            [m[0][2], m[1][2], m[2][2]],
        ])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec3, b: Vec3) -> bool {
        norm(sub(a, b)) < 1e-12
    }

    #[test]
    fn axis_rotation_is_right_handed_and_inverts() {
        let r = Rotation::about_axis([0.0, 0.0, 1.0], std::f64::consts::FRAC_PI_2);
        assert!(close(r.apply([1.0, 0.0, 0.0]), [0.0, 1.0, 0.0]));
        assert!(close(
            r.apply_inverse(r.apply([0.3, -2.0, 5.0])),
            [0.3, -2.0, 5.0]
        ));
        assert!(close(
            r.inverse().apply(r.apply([1.0, 2.0, 3.0])),
            [1.0, 2.0, 3.0]
        ));
    }

    #[test]
    fn between_maps_from_onto_to() {
        for (a, b) in [
            ([1.0, 2.0, 3.0], [-0.5, 0.1, 2.0]),
            ([0.0, 0.0, 1.0], [0.0, 0.0, 5.0]),
            ([0.0, 0.0, 1.0], [0.0, 0.0, -1.0]),
            ([1.0, 0.0, 0.0], [-3.0, 0.0, 0.0]),
        ] {
            let r = Rotation::between(a, b);
            assert!(close(r.apply(normalize(a)), normalize(b)), "{a:?} -> {b:?}");
        }
    }

    #[test]
    fn quaternion_matches_axis_angle() {
        let half = 0.4_f64;
        let axis = normalize([1.0, -2.0, 0.5]);
        let q = [
            half.cos(),
            axis[0] * half.sin(),
            axis[1] * half.sin(),
            axis[2] * half.sin(),
        ];
        let a = Rotation::from_quaternion(q);
        let b = Rotation::about_axis(axis, 2.0 * half);
        let v = [0.7, 0.1, -3.0];
        assert!(close(a.apply(v), b.apply(v)));
        assert_eq!(Rotation::from_quaternion([0.0; 4]), Rotation::IDENTITY);
    }
}
