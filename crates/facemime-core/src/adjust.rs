//! Elastic adjustment of a wire-frame model to contours marked on a frontal image
//! (docs/method.md §2, after Reinders et al.).
//!
//! Everything is 2-D, in image pixels: the model's vertices as projected in the frontal view.
//! A *contour* pairs a chain of model vertices (V_1..V_nv, a polyline through the current
//! vertex positions) with a target polyline on the face (P_1..P_np); nv and np may differ and a
//! single reference point is a contour with one vertex and one target point.
//!
//! Each iteration moves every vertex M by
//!
//! ```text
//! D_M = (1/ε) [ Σ_i S_vi w(M − V_i) / Σ_i w(M − V_i)  −  Σ_j S_pj w(M − Q_j) / Σ_j w(M − Q_j) ]
//! w(d) = exp(−|d|² / ψ²)
//! ```
//!
//! with the push vector S_vi from V_i to the nearest point of the target polyline and the pull
//! vector S_pj from P_j to its nearest point Q_j = P_j + S_pj on the model polyline. The pull
//! therefore moves the model near Q_j by −S_pj, towards P_j. (The paper prints the weight of
//! the pull as w(M − P_j + S_pj); read with S_pj pointing from the model to the face that is the
//! same centre Q_j, but then the sign of the pull term moves the model away from the face, so we
//! keep the geometric meaning: weights centred where each force acts, forces towards the face.)
//! Each weighted mean is further multiplied by the weight of its nearest force, w(d_min): at a
//! force's own position this is exactly the formula, and a vertex far from every force
//! (relative to ψ) stays still instead of copying the nearest force, which is what makes a small
//! ψ a *local* adjustment.
//! ψ (rigidity, pixels) starts large, so the whole face moves together, and shrinks by a factor
//! each iteration for local matching; the loop stops once the contours agree within a
//! tolerance.

use crate::error::Result;
use crate::invalid;

/// One model contour and the face contour it must match.
#[derive(Debug, Clone, PartialEq)]
pub struct Contour {
    /// Model vertex indices along the contour (at least 1).
    pub chain: Vec<usize>,
    /// Target polyline on the image, (x, y) pixels (at least 1 point).
    pub target: Vec<[f64; 2]>,
}

/// Settings of the iteration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Initial rigidity ψ, pixels (> 0).
    pub psi: f64,
    /// Factor applied to ψ after each iteration, in (0, 1].
    pub shrink: f64,
    /// Scaling factor ε (> 0); 2 moves a contour that is offset uniformly by exactly the offset
    /// (push and pull each contribute it once).
    pub epsilon: f64,
    /// Most iterations.
    pub iterations: usize,
    /// Stop once the residual (see [`residual`]) is below this, pixels.
    pub tolerance: f64,
}

/// What the adjustment did.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// Iterations run.
    pub iterations: usize,
    /// Residual before the first and after every iteration, pixels.
    pub residuals: Vec<f64>,
}

/// Nearest point to `p` on the polyline `line` (a single point when it has one vertex).
fn nearest_on(p: [f64; 2], line: impl Iterator<Item = [f64; 2]> + Clone) -> [f64; 2] {
    let mut it = line.clone();
    let first = it.next().expect("non-empty polyline");
    let mut best = first;
    let mut best_d = dist2(p, first);
    let mut a = first;
    for b in it {
        let ab = [b[0] - a[0], b[1] - a[1]];
        let len2 = ab[0] * ab[0] + ab[1] * ab[1];
        let t = if len2 > 0.0 {
            (((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1]) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let q = [a[0] + t * ab[0], a[1] + t * ab[1]];
        let d = dist2(p, q);
        if d < best_d {
            best_d = d;
            best = q;
        }
        a = b;
    }
    best
}

fn dist2(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)
}

fn check(points: &[[f64; 2]], contours: &[Contour], s: &Settings) -> Result<()> {
    if !(s.psi > 0.0 && s.psi.is_finite()) {
        return invalid!("psi must be a positive number of pixels, got {}", s.psi);
    }
    if !(s.shrink > 0.0 && s.shrink <= 1.0) {
        return invalid!("shrink must be in (0, 1], got {}", s.shrink);
    }
    if !(s.epsilon > 0.0 && s.epsilon.is_finite()) {
        return invalid!("epsilon must be positive, got {}", s.epsilon);
    }
    if s.tolerance.is_nan() || s.tolerance < 0.0 {
        return invalid!("tolerance must be >= 0, got {}", s.tolerance);
    }
    if points
        .iter()
        .any(|p| !(p[0].is_finite() && p[1].is_finite()))
    {
        return invalid!("vertices hold NaN or inf");
    }
    for (k, c) in contours.iter().enumerate() {
        if c.chain.is_empty() || c.target.is_empty() {
            return invalid!("contour {k} needs at least one vertex and one target point");
        }
        if let Some(&i) = c.chain.iter().find(|&&i| i >= points.len()) {
            return invalid!(
                "contour {k} uses vertex {i}, but there are {} vertices",
                points.len()
            );
        }
        if c.target
            .iter()
            .any(|p| !(p[0].is_finite() && p[1].is_finite()))
        {
            return invalid!("target of contour {k} holds NaN or inf");
        }
    }
    Ok(())
}

/// Mean over contours of the symmetric mean distance between the model polyline and the target
/// polyline (pixels): how far the contours still disagree.
pub fn residual(points: &[[f64; 2]], contours: &[Contour]) -> f64 {
    if contours.is_empty() {
        return 0.0;
    }
    let total: f64 = contours
        .iter()
        .map(|c| {
            let model = c.chain.iter().map(|&i| points[i]);
            let target = c.target.iter().copied();
            let push: f64 = model
                .clone()
                .map(|v| dist2(v, nearest_on(v, target.clone())).sqrt())
                .sum::<f64>()
                / c.chain.len() as f64;
            let pull: f64 = target
                .clone()
                .map(|p| dist2(p, nearest_on(p, model.clone())).sqrt())
                .sum::<f64>()
                / c.target.len() as f64;
            (push + pull) / 2.0
        })
        .sum();
    total / contours.len() as f64
}

/// Adjusts `points` (the projected model vertices, pixels) in place so that every contour's
/// chain lies on its target. Returns the iterations run and the residual after each.
pub fn elastic(points: &mut [[f64; 2]], contours: &[Contour], s: &Settings) -> Result<Report> {
    check(points, contours, s)?;
    let mut residuals = vec![residual(points, contours)];
    let mut psi = s.psi;
    // Forces as (where it acts, vector): pushes S_vi at V_i, pulls S_pj at Q_j (subtracted).
    let mut push: Vec<([f64; 2], [f64; 2])> = Vec::new();
    let mut pull: Vec<([f64; 2], [f64; 2])> = Vec::new();
    let mut moved = points.to_vec();
    let mut iterations = 0;
    while iterations < s.iterations && residuals[residuals.len() - 1] > s.tolerance {
        push.clear();
        pull.clear();
        for c in contours {
            let model = c.chain.iter().map(|&i| points[i]);
            let target = c.target.iter().copied();
            for v in model.clone() {
                let q = nearest_on(v, target.clone());
                push.push((v, [q[0] - v[0], q[1] - v[1]]));
            }
            for p in target {
                let q = nearest_on(p, model.clone());
                pull.push((q, [q[0] - p[0], q[1] - p[1]]));
            }
        }
        let inv_psi2 = 1.0 / (psi * psi);
        let mean = |m: [f64; 2], forces: &[([f64; 2], [f64; 2])]| -> [f64; 2] {
            let (mut sx, mut sy, mut sw) = (0.0, 0.0, 0.0);
            // Weights relative to the nearest force keep far vertices finite (no 0/0).
            let d0 = forces
                .iter()
                .map(|f| dist2(m, f.0))
                .fold(f64::INFINITY, f64::min);
            for (at, s) in forces {
                let w = (-(dist2(m, *at) - d0) * inv_psi2).exp();
                sx += w * s[0];
                sy += w * s[1];
                sw += w;
            }
            // The weighted mean times w(d_min), the nearest force's weight.
            let fade = (-d0 * inv_psi2).exp() / sw;
            [sx * fade, sy * fade]
        };
        for (k, m) in points.iter().enumerate() {
            let a = mean(*m, &push);
            let b = mean(*m, &pull);
            moved[k] = [
                m[0] + (a[0] - b[0]) / s.epsilon,
                m[1] + (a[1] - b[1]) / s.epsilon,
            ];
        }
        points.copy_from_slice(&moved);
        psi *= s.shrink;
        iterations += 1;
        residuals.push(residual(points, contours));
    }
    Ok(Report {
        iterations,
        residuals,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings() -> Settings {
        Settings {
            psi: 40.0,
            shrink: 0.6,
            epsilon: 2.0,
            iterations: 8,
            tolerance: 0.05,
        }
    }

    fn grid() -> Vec<[f64; 2]> {
        let mut p = Vec::new();
        for y in 0..10 {
            for x in 0..10 {
                p.push([x as f64 * 20.0, y as f64 * 20.0]);
            }
        }
        p
    }

    #[test]
    fn a_contour_moves_onto_its_target() {
        let mut p = grid();
        // Row 5 (y = 100) should lie on a bent line 6 px lower in the middle.
        let chain: Vec<usize> = (50..60).collect();
        let target: Vec<[f64; 2]> = (0..=36)
            .map(|k| {
                let x = k as f64 * 5.0;
                [x, 100.0 + 6.0 * (1.0 - ((x - 90.0) / 90.0).powi(2))]
            })
            .collect();
        let contours = [Contour { chain, target }];
        let r = elastic(&mut p, &contours, &settings()).unwrap();
        assert!(r.residuals[0] > 3.0);
        assert!(*r.residuals.last().unwrap() < 0.5, "{:?}", r.residuals);
        assert!(r.iterations <= 6, "{:?}", r.residuals);
    }

    #[test]
    fn small_psi_leaves_far_vertices_still() {
        let mut p = grid();
        let before = p.clone();
        let contours = [Contour {
            chain: vec![0],
            target: vec![[4.0, 3.0]],
        }];
        let s = Settings {
            psi: 8.0,
            iterations: 1,
            ..settings()
        };
        elastic(&mut p, &contours, &s).unwrap();
        assert!((p[0][0] - 4.0).abs() < 1e-9 && (p[0][1] - 3.0).abs() < 1e-9);
        for (k, (a, b)) in p.iter().zip(&before).enumerate().skip(1) {
            let far = dist2(*b, [0.0, 0.0]).sqrt() >= 40.0;
            if far {
                assert!(
                    dist2(*a, *b).sqrt() < 1e-3,
                    "vertex {k} moved {:?} -> {:?}",
                    b,
                    a
                );
            }
        }
    }

    #[test]
    fn large_psi_moves_the_whole_model_together() {
        let mut p = grid();
        let before = p.clone();
        let contours = [
            Contour {
                chain: vec![0],
                target: vec![[10.0, 0.0]],
            },
            Contour {
                chain: vec![99],
                target: vec![[190.0, 180.0]],
            },
        ];
        let s = Settings {
            psi: 1e4,
            iterations: 1,
            ..settings()
        };
        elastic(&mut p, &contours, &s).unwrap();
        for (a, b) in p.iter().zip(&before) {
            assert!((a[0] - b[0] - 10.0).abs() < 0.01 && (a[1] - b[1]).abs() < 1e-9);
        }
    }

    #[test]
    fn bad_input_is_refused() {
        let mut p = grid();
        let bad = [Contour {
            chain: vec![100],
            target: vec![[0.0, 0.0]],
        }];
        assert!(elastic(&mut p, &bad, &settings()).is_err());
        let empty = [Contour {
            chain: vec![],
            target: vec![[0.0, 0.0]],
        }];
        assert!(elastic(&mut p, &empty, &settings()).is_err());
        let ok = [Contour {
            chain: vec![1],
            target: vec![[0.0, 0.0]],
        }];
        assert!(elastic(
            &mut p,
            &ok,
            &Settings {
                psi: 0.0,
                ..settings()
            }
        )
        .is_err());
        p[3] = [f64::NAN, 0.0];
        assert!(elastic(&mut p, &ok, &settings()).is_err());
    }
}
