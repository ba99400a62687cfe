//! Value noise and fractal sums over an integer-hashed lattice: the only source of texture.
//!
//! Integer hashing, `floor` and plain arithmetic are bit-identical on every IEEE machine, so
//! textures never depend on the platform's maths library.

/// A well-mixed 64-bit hash of a lattice point (SplitMix64 finaliser over the combined keys).
fn hash(seed: u64, x: i64, y: i64, z: i64) -> u64 {
    let mut h = seed ^ 0x9E37_79B9_7F4A_7C15;
    for k in [x, y, z] {
        h = (h ^ k as u64).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        h ^= h >> 29;
    }
    h = h.wrapping_mul(0x94D0_49BB_1331_11EB);
    h ^ (h >> 32)
}

/// Uniform value in `[0, 1)` at a lattice point.
fn lattice(seed: u64, x: i64, y: i64, z: i64) -> f64 {
    (hash(seed, x, y, z) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Uniform value in `[0, 1)` for lattice cell `cell` and draw number `k`: the random features
/// (positions, sizes, tilts) that cellular textures attach to each cell.
pub fn cell_value(seed: u64, cell: [i64; 3], k: u64) -> f64 {
    lattice(
        seed ^ k.wrapping_mul(0xD6E8_FEB8_6659_FD93),
        cell[0],
        cell[1],
        cell[2],
    )
}

/// The cell (of the unit lattice) whose jittered feature point is nearest to `p`: a Voronoi
/// partition, whose cells become the flat facets of rock surfaces.
pub fn nearest_cell3(seed: u64, p: [f64; 3]) -> [i64; 3] {
    let base = [
        p[0].floor() as i64,
        p[1].floor() as i64,
        p[2].floor() as i64,
    ];
    let mut best = (f64::INFINITY, base);
    for dz in -1..=1 {
        for dy in -1..=1 {
            for dx in -1..=1 {
                let cell = [base[0] + dx, base[1] + dy, base[2] + dz];
                let mut d2 = 0.0;
                for k in 0..3 {
                    let feature = cell[k] as f64 + cell_value(seed, cell, k as u64);
                    d2 += (feature - p[k]) * (feature - p[k]);
                }
                if d2 < best.0 {
                    best = (d2, cell);
                }
            }
        }
    }
    best.1
}

/// Cubic fade so that the interpolated noise has a continuous gradient.
fn fade(t: f64) -> f64 {
    t * t * (3.0 - 2.0 * t)
}

fn lerp(a: f64, b: f64, t: f64) -> f64 {
    a + (b - a) * t
}

/// 2-D value noise in `[0, 1)`, one lattice cell per unit.
pub fn value2(seed: u64, x: f64, y: f64) -> f64 {
    let (fx, fy) = (x.floor(), y.floor());
    let (ix, iy) = (fx as i64, fy as i64);
    let (tx, ty) = (fade(x - fx), fade(y - fy));
    let a = lerp(lattice(seed, ix, iy, 0), lattice(seed, ix + 1, iy, 0), tx);
    let b = lerp(
        lattice(seed, ix, iy + 1, 0),
        lattice(seed, ix + 1, iy + 1, 0),
        tx,
    );
    lerp(a, b, ty)
}

/// 3-D value noise in `[0, 1)`, one lattice cell per unit.
pub fn value3(seed: u64, p: [f64; 3]) -> f64 {
    let f = [p[0].floor(), p[1].floor(), p[2].floor()];
    let i = [f[0] as i64, f[1] as i64, f[2] as i64];
    let t = [fade(p[0] - f[0]), fade(p[1] - f[1]), fade(p[2] - f[2])];
    let plane = |dz: i64| {
        let a = lerp(
            lattice(seed, i[0], i[1], i[2] + dz),
            lattice(seed, i[0] + 1, i[1], i[2] + dz),
            t[0],
        );
        let b = lerp(
            lattice(seed, i[0], i[1] + 1, i[2] + dz),
            lattice(seed, i[0] + 1, i[1] + 1, i[2] + dz),
            t[0],
        );
        lerp(a, b, t[1])
    };
    lerp(plane(0), plane(1), t[2])
}

/// Fractal sum of `octaves` octaves of 2-D value noise (frequency doubling, amplitude
/// halving), normalised to `[0, 1)`. Octaves whose wavelength is not at least twice the
/// pixel `footprint` (same units as `x`, `y`) fade to their mean: the far ground would
/// otherwise alias into glitter, and skipping them is also what keeps the far field cheap.
pub fn fbm2(seed: u64, x: f64, y: f64, octaves: u32, footprint: f64) -> f64 {
    let (mut sum, mut norm, mut amplitude, mut frequency) = (0.0, 0.0, 1.0, 1.0);
    for octave in 0..octaves {
        let detail = (1.0 / (frequency * footprint) - 2.0).clamp(0.0, 1.0);
        if detail <= 0.0 {
            sum += amplitude * 0.5;
        } else {
            let n = value2(
                seed.wrapping_add(u64::from(octave).wrapping_mul(0x632B_E59B_D9B4_E019)),
                x * frequency + f64::from(octave) * 17.31,
                y * frequency - f64::from(octave) * 9.77,
            );
            sum += amplitude * (detail * n + (1.0 - detail) * 0.5);
        }
        norm += amplitude;
        amplitude *= 0.5;
        frequency *= 2.0;
    }
    sum / norm
}

/// Fractal sum of 3-D value noise, normalised to `[0, 1)` (rock surfaces, seen close).
pub fn fbm3(seed: u64, p: [f64; 3], octaves: u32) -> f64 {
    let (mut sum, mut norm, mut amplitude, mut frequency) = (0.0, 0.0, 1.0, 1.0);
    for octave in 0..octaves {
        let shift = f64::from(octave) * 5.37;
        sum += amplitude
            * value3(
                seed.wrapping_add(u64::from(octave).wrapping_mul(0x632B_E59B_D9B4_E019)),
                [
                    p[0] * frequency + shift,
                    p[1] * frequency - shift,
                    p[2] * frequency + 2.0 * shift,
                ],
            );
        norm += amplitude;
        amplitude *= 0.5;
        frequency *= 2.0;
    }
    sum / norm
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_is_bounded_continuous_and_seeded() {
        let mut differs = false;
        for i in 0..2000 {
            let x = f64::from(i) * 0.0137 - 7.0;
            let y = f64::from(i) * 0.0291 + 3.0;
            let v = value2(1, x, y);
            assert!((0.0..1.0).contains(&v));
            assert!((value2(1, x + 1e-7, y) - v).abs() < 1e-5, "continuous");
            let w = value3(2, [x, y, x - y]);
            assert!((0.0..1.0).contains(&w));
            let f = fbm2(3, x, y, 6, 0.01);
            assert!((0.0..1.0).contains(&f));
            differs |= (value2(4, x, y) - v).abs() > 1e-3;
        }
        assert!(differs, "the seed changes the noise");
    }

    #[test]
    fn nearest_cell_owns_its_feature_point() {
        for i in 0..200 {
            let cell = [i - 100, 3 * i % 17, -(i % 5)];
            let feature = [0, 1, 2].map(|k| cell[k] as f64 + cell_value(8, cell, k as u64));
            assert_eq!(nearest_cell3(8, feature), cell);
        }
    }

    #[test]
    fn coarse_footprint_flattens_fine_octaves() {
        // With a footprint larger than every wavelength, only the mean remains.
        assert_eq!(fbm2(9, 0.3, 0.7, 5, 100.0), 0.5);
    }
}
