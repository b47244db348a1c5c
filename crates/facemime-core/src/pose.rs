//! Orthographic head-pose fit: the pose (yaw, pitch, roll, scale, translation) that maps 3D
//! model points onto their image positions, by Gauss-Newton with Huber weights.
//!
//! Model space: right-handed, x to the subject's left, y up, z towards the camera (model units).
//! Image: pixels, x right, y down. A model point X projects to
//! `(u, v) = s·(R X)_x + tx, −s·(R X)_y + ty` with `R = Rz(roll)·Rx(pitch)·Ry(yaw)` (degrees).
//! Parameters are `[yaw, pitch, roll (degrees), ln s, tx, ty (pixels)]`.

type Mat3 = [[f64; 3]; 3];

/// `Rz(roll)·Rx(pitch)·Ry(yaw)`, angles in degrees (the Python `rotation_matrix`).
pub fn rotation(yaw: f64, pitch: f64, roll: f64) -> Mat3 {
    let (sy, cy) = yaw.to_radians().sin_cos();
    let (sp, cp) = pitch.to_radians().sin_cos();
    let (sr, cr) = roll.to_radians().sin_cos();
    let ry = [[cy, 0.0, sy], [0.0, 1.0, 0.0], [-sy, 0.0, cy]];
    let rx = [[1.0, 0.0, 0.0], [0.0, cp, -sp], [0.0, sp, cp]];
    let rz = [[cr, -sr, 0.0], [sr, cr, 0.0], [0.0, 0.0, 1.0]];
    mul(&mul(&rz, &rx), &ry)
}

fn mul(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut c = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}

fn transpose(a: &Mat3) -> Mat3 {
    let mut t = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            t[i][j] = a[j][i];
        }
    }
    t
}

/// Generators of the rotations about y, x and z (d/dθ of each axis rotation at θ = 0).
const GY: Mat3 = [[0.0, 0.0, 1.0], [0.0, 0.0, 0.0], [-1.0, 0.0, 0.0]];
const GX: Mat3 = [[0.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]];
const GZ: Mat3 = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]];

/// Reprojection residuals, one (u, v) pair per point, of model points `x` against `target` at
/// parameters `p`, and their analytic Jacobian rows (∂/∂p of u and of v per point).
/// ∂R/∂yaw = R·Gy, ∂R/∂pitch = Rz·Gx·Rzᵀ·R, ∂R/∂roll = Gz·R (per radian).
pub fn residuals(
    x: &[[f64; 3]],
    target: &[[f64; 2]],
    p: &[f64; 6],
) -> Vec<([f64; 2], [[f64; 6]; 2])> {
    let rot = rotation(p[0], p[1], p[2]);
    let rz = rotation(0.0, 0.0, p[2]);
    let mats = [
        rot,
        mul(&rot, &GY),
        mul(&mul(&mul(&rz, &GX), &transpose(&rz)), &rot),
        mul(&GZ, &rot),
    ];
    let (s, rad) = (p[3].exp(), 1f64.to_radians());
    x.iter()
        .zip(target)
        .map(|(xm, t)| {
            // q[k] = s·(mats[k]·x) in (u, −v) rows: the image-plane image of each derivative.
            let q: Vec<[f64; 2]> = mats
                .iter()
                .map(|m| {
                    let row = |i: usize| s * (m[i][0] * xm[0] + m[i][1] * xm[1] + m[i][2] * xm[2]);
                    [row(0), -row(1)]
                })
                .collect();
            let r = [q[0][0] + p[4] - t[0], q[0][1] + p[5] - t[1]];
            let jac = |i: usize| {
                let mut row = [
                    rad * q[1][i],
                    rad * q[2][i],
                    rad * q[3][i],
                    q[0][i],
                    0.0,
                    0.0,
                ];
                row[4 + i] = 1.0;
                row
            };
            (r, [jac(0), jac(1)])
        })
        .collect()
}

/// Settings of [`fit`].
pub struct FitSettings {
    /// Huber threshold on a point's reprojection distance (pixels).
    pub huber: f64,
    /// Weight (px² per degree²) holding yaw and pitch at `anchor`.
    pub prior: f64,
    /// The (yaw, pitch) the prior holds them at (degrees).
    pub anchor: [f64; 2],
    /// Gauss-Newton iterations at most; it stops earlier when no angle moves 1e-3° and no
    /// translation 1e-3 px.
    pub iterations: usize,
}

/// The parameters that map `x` (model points) onto `target` (pixels), from `start`.
pub fn fit(
    x: &[[f64; 3]],
    target: &[[f64; 2]],
    start: [f64; 6],
    settings: &FitSettings,
) -> [f64; 6] {
    let mut p = start;
    for _ in 0..settings.iterations {
        let mut h = [[0.0; 6]; 6];
        let mut g = [0.0; 6];
        for (r, jac) in residuals(x, target, &p) {
            let w = (settings.huber / r[0].hypot(r[1]).max(1e-9)).min(1.0);
            for (ri, row) in r.iter().zip(&jac) {
                for a in 0..6 {
                    g[a] += w * row[a] * ri;
                    for b in 0..6 {
                        h[a][b] += w * row[a] * row[b];
                    }
                }
            }
        }
        for a in 0..2 {
            h[a][a] += settings.prior;
            g[a] += settings.prior * (p[a] - settings.anchor[a]);
        }
        for (a, row) in h.iter_mut().enumerate() {
            row[a] += 1e-9;
        }
        let step = solve(h, g.map(|v| -v));
        for (pa, sa) in p.iter_mut().zip(&step) {
            *pa += sa;
        }
        let small = |r: std::ops::Range<usize>| step[r].iter().all(|v| v.abs() < 1e-3);
        if small(0..3) && small(4..6) {
            break;
        }
    }
    p
}

/// Solves `a·x = b` (6×6) by Gaussian elimination with partial pivoting.
fn solve(mut a: [[f64; 6]; 6], mut b: [f64; 6]) -> [f64; 6] {
    for col in 0..6 {
        let pivot = (col..6)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap_or(col);
        a.swap(col, pivot);
        b.swap(col, pivot);
        let (pivot_row, pivot_b) = (a[col], b[col]);
        for row in col + 1..6 {
            let f = a[row][col] / pivot_row[col];
            for (v, p) in a[row][col..].iter_mut().zip(&pivot_row[col..]) {
                *v -= f * p;
            }
            b[row] -= f * pivot_b;
        }
    }
    let mut x = [0.0; 6];
    for row in (0..6).rev() {
        let tail: f64 = (row + 1..6).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - tail) / a[row][row];
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    fn project(x: &[[f64; 3]], p: &[f64; 6]) -> Vec<[f64; 2]> {
        let (r, s) = (rotation(p[0], p[1], p[2]), p[3].exp());
        x.iter()
            .map(|v| {
                let row = |i: usize| r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2];
                [s * row(0) + p[4], -s * row(1) + p[5]]
            })
            .collect()
    }

    fn cloud() -> Vec<[f64; 3]> {
        (0..40)
            .map(|k| {
                let t = k as f64;
                [
                    60.0 * (t * 0.7).sin(),
                    70.0 * (t * 1.3).cos(),
                    30.0 * (t * 0.4).sin(),
                ]
            })
            .collect()
    }

    #[test]
    fn yaw_90_turns_the_nose_to_the_subjects_left() {
        let r = rotation(90.0, 0.0, 0.0);
        let nose = [r[0][2], r[1][2], r[2][2]];
        assert!((nose[0] - 1.0).abs() < 1e-12 && nose[1].abs() < 1e-12 && nose[2].abs() < 1e-12);
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let x = cloud();
        let target: Vec<[f64; 2]> = x.iter().map(|v| [v[0] + 200.0, v[1] + 240.0]).collect();
        let p = [12.0, -7.0, 5.0, 2.3f64.ln(), 250.0, 240.0];
        let at = |q: &[f64; 6]| residuals(&x, &target, q);
        let base = at(&p);
        for (m, (r, _)) in base.iter().enumerate() {
            let projected = project(&x[m..m + 1], &p)[0];
            assert!((r[0] - (projected[0] - target[m][0])).abs() < 1e-9);
            assert!((r[1] - (projected[1] - target[m][1])).abs() < 1e-9);
        }
        for k in 0..6 {
            let (mut lo, mut hi) = (p, p);
            lo[k] -= 1e-5;
            hi[k] += 1e-5;
            let (rl, rh) = (at(&lo), at(&hi));
            for m in 0..x.len() {
                for i in 0..2 {
                    let numeric = (rh[m].0[i] - rl[m].0[i]) / 2e-5;
                    assert!(
                        (base[m].1[i][k] - numeric).abs() < 1e-4,
                        "point {m} row {i} parameter {k}"
                    );
                }
            }
        }
    }

    #[test]
    fn fit_recovers_a_known_pose_exactly_and_despite_outliers_closely() {
        let x = cloud();
        let truth = [18.0, -7.0, 5.0, 2.2f64.ln(), 260.0, 240.0];
        let settings = FitSettings {
            huber: 1.5,
            prior: 1e-6,
            anchor: [0.0, 0.0],
            iterations: 30,
        };
        let start = [0.0, 0.0, 0.0, 2f64.ln(), 250.0, 250.0];
        let mut target = project(&x, &truth);
        let p = fit(&x, &target, start, &settings);
        assert!(
            p.iter().zip(&truth).all(|(g, w)| (g - w).abs() < 1e-4),
            "{p:?} vs {truth:?}"
        );
        // Six of 40 points moved 25 px (with the face's expression): Huber weights keep the
        // pose within a fraction of a degree and a pixel.
        for t in target.iter_mut().take(6) {
            t[0] += 25.0;
        }
        let p = fit(&x, &target, start, &settings);
        let off = p
            .iter()
            .zip(&truth)
            .map(|(g, w)| (g - w).abs())
            .collect::<Vec<_>>();
        assert!(
            off[..3].iter().all(|&d| d < 0.3)
                && off[3] < 0.005
                && off[4..].iter().all(|&d| d < 0.5),
            "{p:?}"
        );
    }
}
