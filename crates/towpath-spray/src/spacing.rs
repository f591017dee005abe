//! Pass spacing: the thickness an endless raster leaves on a plane (a closed-form sum of shifted
//! line integrals of the profile), its ripple, and the spacing that minimises the ripple
//! (Tewolde & Sheng 2008 §III-B: the nominal spacing "calculated by minimizing the thickness
//! square error").
//!
//! Straight parallel passes `d` apart at speed v with flow F on a plane square to the gun at
//! the standoff leave `T(y) = F/v · Σ_k G(y − k d)` at offset y across the passes, G the
//! profile's [line integral](crate::Profile::line_integral). T has period d and mean F/(v d);
//! its relative RMS deviation over a period is the ripple E(d), independent of F and v. E
//! falls to zero as d → 0 (and passes multiply), so the optimiser searches
//! d ∈ [0.6 R, 1.8 R]: below 0.6 R a β = 2 raster is already uniform to a third of a percent
//! at the cost of 25–60 % more passes; above 1.8 R stripes show whatever the profile.

use crate::profile::Profile;

/// The spacing range the optimiser searches, in footprint radii.
pub const SPACING_RANGE: (f64, f64) = (0.6, 1.8);

/// Offsets per period at which the ripple is evaluated (midpoint rule).
const RIPPLE_SAMPLES: usize = 128;

/// `Σ_k G(y − k d)`: the thickness of an endless raster at offset `y` from a pass, per unit
/// F/v (1/mm).
pub fn raster_sum(profile: &Profile, radius: f64, spacing: f64, y: f64) -> f64 {
    let k0 = ((y - radius) / spacing).floor() as i64;
    let k1 = ((y + radius) / spacing).ceil() as i64;
    (k0..=k1).map(|k| profile.line_integral(y - k as f64 * spacing, radius)).sum()
}

/// E(d): the relative RMS deviation of the endless raster's thickness from its mean, over one
/// period.
pub fn ripple(profile: &Profile, radius: f64, spacing: f64) -> f64 {
    let n = RIPPLE_SAMPLES;
    let vals: Vec<f64> =
        (0..n).map(|i| raster_sum(profile, radius, spacing, (i as f64 + 0.5) * spacing / n as f64)).collect();
    let mean = vals.iter().sum::<f64>() / n as f64;
    if !(mean > 0.0) {
        return f64::INFINITY;
    }
    let var = vals.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n as f64;
    var.sqrt() / mean
}

/// The spacing the optimiser chose and its ripple.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SpacingChoice {
    /// Spacing (mm).
    pub spacing: f64,
    /// E at that spacing (relative RMS, 0.01 = 1 %).
    pub ripple: f64,
}

/// The spacing in [`SPACING_RANGE`] that minimises E: a scan of 241 spacings, then golden-
/// section search in the bracket around the best.
pub fn optimal_spacing(profile: &Profile, radius: f64) -> SpacingChoice {
    let (lo, hi) = (SPACING_RANGE.0 * radius, SPACING_RANGE.1 * radius);
    let n = 240;
    let at = |i: usize| lo + (hi - lo) * i as f64 / n as f64;
    let mut best = (0, f64::INFINITY);
    for i in 0..=n {
        let e = ripple(profile, radius, at(i));
        if e < best.1 {
            best = (i, e);
        }
    }
    let (mut a, mut b) = (at(best.0.saturating_sub(1)), at((best.0 + 1).min(n)));
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let (mut fc, mut fd) = (ripple(profile, radius, c), ripple(profile, radius, d));
    while b - a > 1e-7 * radius {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = ripple(profile, radius, c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = ripple(profile, radius, d);
        }
    }
    let mid = 0.5 * (a + b);
    let (fm, fbest) = (ripple(profile, radius, mid), best.1);
    if fm <= fbest {
        SpacingChoice { spacing: mid, ripple: fm }
    } else {
        SpacingChoice { spacing: at(best.0), ripple: fbest }
    }
}

/// Fits a whole number of passes into a width: `n` passes `width / n` apart (the first and last
/// half a spacing inside the edges), `n` among the two counts nearest `width / spacing` with the
/// smaller ripple. Returns (n, spacing).
pub fn fit(profile: &Profile, radius: f64, width: f64, spacing: f64) -> (usize, f64) {
    if !(width > spacing) {
        return (1, width.max(spacing * 1e-3).min(spacing));
    }
    let x = width / spacing;
    let cands = [x.floor().max(1.0) as usize, x.ceil() as usize];
    let mut best = (cands[0], f64::INFINITY);
    for &n in &cands {
        let e = ripple(profile, radius, width / n as f64);
        if e < best.1 - 1e-12 {
            best = (n, e);
        }
    }
    (best.0, width / best.0 as f64)
}

/// What lies beyond one side of a patch, across its passes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// A free edge or a crease: the patch's own passes run out past it.
    Free,
    /// A seam: the neighbour's passes continue the raster; the patch's passes stop at it.
    Seam,
}

/// The profile's line integral G tabulated on [0, R] (linear interpolation; G is even).
struct LineTable {
    step: f64,
    values: Vec<f64>,
}

impl LineTable {
    const N: usize = 1024;

    fn new(profile: &Profile, radius: f64) -> LineTable {
        let step = radius / Self::N as f64;
        let values = (0..=Self::N).map(|i| profile.line_integral(i as f64 * step, radius)).collect();
        LineTable { step, values }
    }

    fn at(&self, y: f64) -> f64 {
        let t = y.abs() / self.step;
        let i = t.floor() as usize;
        if i >= Self::N {
            return 0.0;
        }
        let f = t - i as f64;
        self.values[i] * (1.0 - f) + self.values[i + 1] * f
    }
}

/// A pass layout across one patch (in one dimension, across the passes).
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// Spacing (mm).
    pub spacing: f64,
    /// The patch's own passes: offsets across the sweep (mm; the patch spans [0, width]).
    pub passes: Vec<f64>,
    /// The neighbours' passes continuing the raster across seams.
    pub neighbours: Vec<f64>,
    /// Square-root mean square error of the thickness over [0, width], relative to the target,
    /// with every pass at the speed `F / (t d)` of its own spacing d (see [`layout_error`]).
    pub error: f64,
}

/// The relative RMS error of the thickness over `[0, width]` left by passes at offsets `own`
/// with spacing `d` and by neighbour passes at offsets `neighbours` with spacing `dn`, every pass
/// at the speed that gives the target on an endless raster of its spacing (so a pass at spacing
/// d leaves `t · d · G(y)`): `sqrt(mean_y (d Σ G(y − x) + dn Σ G(y − x') − 1)²)`, on `samples`
/// evenly spaced points.
pub fn layout_error(
    profile: &Profile,
    radius: f64,
    width: f64,
    own: (&[f64], f64),
    neighbours: (&[f64], f64),
    samples: usize,
) -> f64 {
    layout_error_table(&LineTable::new(profile, radius), radius, width, own, neighbours, samples)
}

fn layout_error_table(
    table: &LineTable,
    radius: f64,
    width: f64,
    own: (&[f64], f64),
    neighbours: (&[f64], f64),
    samples: usize,
) -> f64 {
    let m = samples.max(1);
    let dy = width / m as f64;
    let mut t = vec![0.0; m];
    for (xs, d) in [own, neighbours] {
        for &x in xs {
            // Samples within R of x.
            let i0 = (((x - radius) / dy - 0.5).floor().max(0.0)) as usize;
            let i1 = (((x + radius) / dy - 0.5).ceil().max(0.0) as usize).min(m.saturating_sub(1));
            for (i, ti) in t.iter_mut().enumerate().take(i1 + 1).skip(i0) {
                *ti += d * table.at((i as f64 + 0.5) * dy - x);
            }
        }
    }
    (t.iter().map(|v| (v - 1.0) * (v - 1.0)).sum::<f64>() / m as f64).sqrt()
}

/// Evaluation points for a width: at least 16 per smallest spacing, 32 to 2048.
fn samples_for(width: f64, radius: f64) -> usize {
    ((16.0 * width / (SPACING_RANGE.0 * radius)).ceil() as usize).clamp(32, 2048)
}

/// Zigzag offsets across a patch of width `width` at spacing `d` (see [`zigzag_layout`]).
pub fn zigzag_offsets(width: f64, d: f64, lo: Side, hi: Side, runout: f64) -> Vec<f64> {
    // The lattice sits half a spacing inside a seam; with a seam on the high side only, it is
    // anchored there.
    let anchor = match (lo, hi) {
        (Side::Free, Side::Seam) => width - ((width / d).floor() + 1.0) * d,
        _ => 0.0,
    };
    let lo_limit = if lo == Side::Free { -runout } else { 0.0 };
    let hi_limit = if hi == Side::Free { width + runout } else { width };
    let kmin = ((lo_limit - anchor) / d - 0.5).floor() as i64;
    let kmax = ((hi_limit - anchor) / d - 0.5).ceil() as i64;
    (kmin..=kmax)
        .map(|k| anchor + (k as f64 + 0.5) * d)
        .filter(|&x| x > lo_limit - 1e-9 && x < hi_limit + 1e-9)
        .collect()
}

/// Neighbour passes across the seams of a patch of width `width`: a raster of spacing `dn`
/// starting half a spacing past each seam side, as far as it reaches into the patch.
fn seam_neighbours(width: f64, dn: f64, lo: Side, hi: Side, radius: f64) -> Vec<f64> {
    let mut out = Vec::new();
    let n = (radius / dn).ceil() as usize + 1;
    for k in 0..n {
        let o = (k as f64 + 0.5) * dn;
        if lo == Side::Seam {
            out.push(-o);
        }
        if hi == Side::Seam {
            out.push(width + o);
        }
    }
    out
}

/// Searches a spacing in `[lo, hi]` minimising `err`: a scan of 48 steps (and `extra`), then
/// golden-section search in the bracket around the best.
fn search(lo: f64, hi: f64, extra: f64, err: &dyn Fn(f64) -> f64) -> (f64, f64) {
    let n = 48;
    let at = |i: usize| lo + (hi - lo) * i as f64 / n as f64;
    let mut best = (extra, err(extra));
    let mut best_i = None;
    for i in 0..=n {
        let e = err(at(i));
        if e < best.1 {
            best = (at(i), e);
            best_i = Some(i);
        }
    }
    let Some(bi) = best_i else { return best };
    let (mut a, mut b) = (at(bi.saturating_sub(1)), at((bi + 1).min(n)));
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
    let (mut fc, mut fd) = (err(c), err(d));
    for _ in 0..30 {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = err(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = err(d);
        }
    }
    for (x, f) in [(c, fc), (d, fd)] {
        if f < best.1 {
            best = (x, f);
        }
    }
    best
}

/// The zigzag layout of a patch `width` wide (measured across the passes) whose spacing
/// minimises the thickness square error over the patch ([`layout_error`], Tewolde & Sheng 2008
/// §III-B): passes half a spacing inside seams (with a seam on both sides, a whole number of
/// passes fills the width), running out `runout` past free sides, the neighbours' rasters at
/// spacing `dn` continuing across seams. `fixed` gives the spacing instead of searching it.
pub fn zigzag_layout(
    profile: &Profile,
    radius: f64,
    width: f64,
    sides: (Side, Side),
    runout: f64,
    dn: f64,
    fixed: Option<f64>,
) -> Layout {
    let (lo, hi) = sides;
    let table = LineTable::new(profile, radius);
    let m = samples_for(width, radius);
    let nb = seam_neighbours(width, dn, lo, hi, radius);
    let err = |d: f64| {
        let own = zigzag_offsets(width, d, lo, hi, runout);
        layout_error_table(&table, radius, width, (&own, d), (&nb, dn), m)
    };
    let d = match fixed {
        Some(d) => d,
        None if lo == Side::Seam && hi == Side::Seam => {
            // A whole number of passes: every count whose spacing is in range, and the counts
            // next to width / dn.
            let (dlo, dhi) = (SPACING_RANGE.0 * radius, SPACING_RANGE.1 * radius);
            let x = width / dn;
            let mut counts: Vec<usize> = ((width / dhi).ceil().max(1.0) as usize..=(width / dlo).floor() as usize)
                .filter(|&n| (n as f64 - x).abs() <= 3.0)
                .collect();
            counts.push(x.floor().max(1.0) as usize);
            counts.push(x.ceil().max(1.0) as usize);
            counts
                .into_iter()
                .map(|n| width / n as f64)
                .map(|d| (d, err(d)))
                .min_by(|a, b| a.1.total_cmp(&b.1).then(b.0.total_cmp(&a.0)))
                .map_or(dn, |b| b.0)
        }
        None => search(SPACING_RANGE.0 * radius, SPACING_RANGE.1 * radius, dn, &err).0,
    };
    let passes = zigzag_offsets(width, d, lo, hi, runout);
    let error = layout_error_table(&table, radius, width, (&passes, d), (&nb, dn), m);
    Layout { spacing: d, passes, neighbours: nb, error }
}

/// The ring spacing of a spiral whose rings lie `(k + ½) d` inside the border of a patch with
/// largest inner border distance `depth`, and `(k + ½) d` outside it within `runout`,
/// minimising the thickness square error across the patch through its centre (the rings seen on
/// a cross-section `2·depth` wide, mirrored about the centre). Returns (spacing, error).
pub fn spiral_spacing(profile: &Profile, radius: f64, depth: f64, runout: f64, d0: f64) -> (f64, f64) {
    let table = LineTable::new(profile, radius);
    let width = 2.0 * depth;
    let m = samples_for(width, radius);
    let err = |d: f64| {
        let mut xs = Vec::new();
        let mut k = 0;
        while (k as f64 + 0.5) * d < depth {
            let x = (k as f64 + 0.5) * d;
            xs.push(x);
            xs.push(width - x);
            k += 1;
        }
        let mut k = 0;
        while (k as f64 + 0.5) * d < runout {
            let x = (k as f64 + 0.5) * d;
            xs.push(-x);
            xs.push(width + x);
            k += 1;
        }
        layout_error_table(&table, radius, width, (&xs, d), (&[], 0.0), m)
    };
    search(SPACING_RANGE.0 * radius, SPACING_RANGE.1 * radius, d0, &err)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn raster_mean_is_one_over_spacing() {
        let p = Profile::Beta { beta: 2.0 };
        for d in [20.0, 37.0, 61.0] {
            let n = 1000;
            let m: f64 =
                (0..n).map(|i| raster_sum(&p, 50.0, d, (i as f64 + 0.5) * d / n as f64)).sum::<f64>() / n as f64;
            assert!((m * d - 1.0).abs() < 1e-6, "{d}: {}", m * d);
        }
    }

    #[test]
    fn optimiser_finds_the_minimum_of_the_ripple_curve() {
        for (p, r) in [
            (Profile::Beta { beta: 2.0 }, 50.0),
            (Profile::Beta { beta: 3.0 }, 25.0),
            (Profile::Gauss { sigma: 20.0 }, 50.0),
        ] {
            let got = optimal_spacing(&p, r);
            // Brute force: a scan ten times finer than the optimiser's.
            let (lo, hi) = (SPACING_RANGE.0 * r, SPACING_RANGE.1 * r);
            let n = 2400;
            let brute = (0..=n)
                .map(|i| lo + (hi - lo) * i as f64 / n as f64)
                .map(|d| (d, ripple(&p, r, d)))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap();
            assert!(got.ripple <= brute.1 + 1e-9, "{p}: {got:?} vs {brute:?}");
            assert!((got.spacing - brute.0).abs() < (hi - lo) / n as f64 * 2.0, "{p}: {got:?} vs {brute:?}");
            assert!(got.spacing >= lo && got.spacing <= hi);
        }
        // β = 2: the known minimum near 0.744 R, below 1 %; a poor spacing (0.95 R) is 4–8 %.
        let p = Profile::Beta { beta: 2.0 };
        let got = optimal_spacing(&p, 1.0);
        assert!((got.spacing - 0.744).abs() < 0.005 && got.ripple < 0.01, "{got:?}");
        let poor = ripple(&p, 1.0, 0.95);
        assert!(poor > 0.04 && poor < 0.09, "{poor}");
    }

    #[test]
    fn fit_puts_a_whole_number_of_passes() {
        let p = Profile::Beta { beta: 2.0 };
        let (n, d) = fit(&p, 50.0, 400.0, 37.2);
        assert!(n == 10 || n == 11);
        assert!((n as f64 * d - 400.0).abs() < 1e-9);
        assert_eq!(fit(&p, 50.0, 20.0, 37.2).0, 1);
    }

    #[test]
    fn a_wide_free_layout_has_the_endless_ripple() {
        // Far from the edges a layout is the endless raster: over 40 whole periods with run-outs
        // past both edges, the layout error equals the ripple computed from the exact integral.
        let p = Profile::Beta { beta: 2.0 };
        for d in [30.0, 37.2, 47.5, 60.0] {
            let w = 40.0 * d;
            let own = zigzag_offsets(w, d, Side::Free, Side::Free, 50.0);
            let e = layout_error(&p, 50.0, w, (&own, d), (&[], 0.0), 40 * 128);
            let r = ripple(&p, 50.0, d);
            assert!((e - r).abs() < 1e-3, "d {d}: layout {e} vs ripple {r}");
        }
    }

    #[test]
    fn patch_spacing_is_the_minimum_of_the_patch_error() {
        let p = Profile::Beta { beta: 2.0 };
        let (r, dn) = (50.0, optimal_spacing(&p, 50.0).spacing);
        let samples = 2048;
        for (w, sides) in
            [(333.0, (Side::Free, Side::Free)), (333.0, (Side::Free, Side::Seam)), (171.0, (Side::Seam, Side::Free))]
        {
            let got = zigzag_layout(&p, r, w, sides, r, dn, None);
            // Brute force: every spacing of a fine scan, the error recomputed independently of
            // the search.
            let err = |d: f64| {
                let own = zigzag_offsets(w, d, sides.0, sides.1, r);
                let nb: Vec<f64> = (0..4)
                    .flat_map(|k| {
                        let o = (k as f64 + 0.5) * dn;
                        let mut v = Vec::new();
                        if sides.0 == Side::Seam {
                            v.push(-o);
                        }
                        if sides.1 == Side::Seam {
                            v.push(w + o);
                        }
                        v
                    })
                    .collect();
                layout_error(&p, r, w, (&own, d), (&nb, dn), samples)
            };
            let n = 600;
            let brute = (0..=n)
                .map(|i| SPACING_RANGE.0 * r + (SPACING_RANGE.1 - SPACING_RANGE.0) * r * i as f64 / n as f64)
                .map(|d| (d, err(d)))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap();
            let mine = err(got.spacing);
            assert!(mine <= brute.1 + 2e-4, "{w} {sides:?}: {} ({mine}) vs brute {brute:?}", got.spacing);
            assert!(mine <= err(dn) + 1e-12, "never worse than the endless optimum");
        }
        // Two seams: a whole number of passes, the best count.
        let w = 400.0;
        let got = zigzag_layout(&p, r, w, (Side::Seam, Side::Seam), r, dn, None);
        let n = (w / got.spacing).round();
        assert!((n * got.spacing - w).abs() < 1e-9);
        assert_eq!(got.passes.len(), n as usize);
        for k in 4..=13 {
            let alt = zigzag_layout(&p, r, w, (Side::Seam, Side::Seam), r, dn, Some(w / k as f64));
            assert!(got.error <= alt.error + 1e-12, "{k} passes: {} < {}", alt.error, got.error);
        }
    }
}
