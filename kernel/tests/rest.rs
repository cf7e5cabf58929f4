//! The steady rest's track on the current surface during a pass.

use pilgrim_kernel::families::revolution::rest::{track, RestSetup, RestTrack};
use pilgrim_kernel::families::revolution::surface::{GroundSurface, WheelSection};
use pilgrim_kernel::profile::Polyline;
use pilgrim_kernel::{drop_circle, equidistant, MandrelLaw, Profile, ProfileError, Side};

const R_S: f64 = 20.0;
const R_O: f64 = 25.0;

fn setup(b: f64) -> RestSetup {
    RestSetup {
        radius: R_O,
        offset_b: b,
        sample: 0.05,
        tolerance: 0.002,
    }
}

/// The rest's track over `stock` while the wheel moves along `(cz, cx)`,
/// its feed per revolution so small that it leaves no ridge (1e-4 mm: a
/// ridge of 6e-11 mm): the continuous sweep.
fn ridge_free(stock: &Profile, cz: &[f64], cx: &[f64], b: f64) -> Result<RestTrack, ProfileError> {
    let wheel = WheelSection {
        radius: R_S,
        flat: 0.0,
    };
    let path = Polyline::new(cz.to_vec(), cx.to_vec()).unwrap();
    track(
        &GroundSurface::new(stock.clone()),
        &path,
        wheel,
        100.0,
        None,
        1e6,
        &setup(b),
    )
}

/// A bar of radius 30 turned to 29.9 from z = 50 to 250: behind the wheel
/// the rest rides 29.9, ahead of it 30, and between the two never lower
/// than the cut nor higher than the stock.
#[test]
fn rest_rides_the_cut_behind_the_wheel_and_the_stock_ahead() {
    let z: Vec<f64> = (-200..=500).map(|i| i as f64).collect();
    let bar = Profile::new(z, vec![30.0; 701]).unwrap();
    let cz: Vec<f64> = (0..=200).map(|i| 50.0 + i as f64).collect();
    let cx = vec![29.9 + R_S; cz.len()];
    let behind = ridge_free(&bar, &cz, &cx, -100.0).unwrap();
    let ahead = ridge_free(&bar, &cz, &cx, 100.0).unwrap();
    for (k, &zk) in behind.path.z.iter().enumerate() {
        let z_r = zk - 100.0;
        let u = behind.centre_x[k];
        assert!(
            (29.9 + R_O - 1e-9..=30.0 + R_O + 1e-9).contains(&u),
            "block {k}: {u}"
        );
        // On the cut, within 1e-5 mm (the crest over spindle phases is the
        // cut raised by a ridge of 6e-11 mm at this feed).
        if z_r - R_O >= 50.0 + R_S {
            assert!(
                (u - (29.9 + R_O)).abs() <= 1e-5,
                "block {k}: on the cut, {u}"
            );
        }
        if z_r + R_O <= 50.0 - R_S {
            assert!(
                (u - (30.0 + R_O)).abs() < 1e-9,
                "block {k}: on the stock, {u}"
            );
        }
    }
    for (k, u) in ahead.centre_x.iter().enumerate() {
        assert!((u - (30.0 + R_O)).abs() < 1e-9, "ahead, block {k}");
    }
    // Along the pass the rest comes down, never up.
    assert!(behind.centre_x.windows(2).all(|w| w[1] <= w[0] + 1e-12));
    // A rest that misses the work is named.
    let e = ridge_free(&bar, &cz, &cx, -600.0).unwrap_err().to_string();
    assert!(
        e.contains("support at point 1 of the pass") && e.contains("at z = -550.0000"),
        "{e}"
    );
}

/// On a mandrel pass the track agrees, within 1 um, with an independent
/// simulation: the surface sampled five times finer as the minimum of the
/// stock and every circle the wheel has placed so far, and the exact drop
/// on it. So the rest neither presses into the current surface nor stands
/// off it by more than that.
#[test]
fn rest_track_matches_an_independent_simulation() {
    let law = MandrelLaw::new(38.0, 52.0, 400.0, 0.012, 2.3).unwrap();
    let finished = law.profile(0.05, 0.0).unwrap();
    // The stock: 0.1 mm over the law, running on flat beyond the working part.
    let sz: Vec<f64> = (0..=16_000).map(|i| -200.0 + i as f64 * 0.05).collect();
    let sx: Vec<f64> = sz
        .iter()
        .map(|z| law.x(z.clamp(0.0, 400.0)) + 0.1)
        .collect();
    let stock = Profile::new(sz, sx).unwrap();
    let e = equidistant(&finished, R_S, Side::Outside).unwrap();
    // Every 40th point of the equidistant, z decreasing (a pass to the left).
    let idx: Vec<usize> = (0..e.z.len()).rev().step_by(40).collect();
    let (cz, cx): (Vec<f64>, Vec<f64>) = idx.iter().map(|&i| (e.z[i], e.x[i])).unzip();
    for b in [150.0, -60.0, 30.0] {
        let t = ridge_free(&stock, &cz, &cx, b).unwrap();
        // The track's path: the wheel's points and any the rest added.
        let (cz, cx) = (&t.path.z, &t.path.x);
        let (dz, dx, block_of) = pilgrim_kernel::offset::swept_circles(cz, cx, R_S, 1e-5).unwrap();
        for k in (0..cz.len()).step_by(7) {
            let z_r = cz[k] + b;
            let (a, c) = ((z_r - R_O).max(-200.0), (z_r + R_O).min(600.0));
            if a >= c {
                continue;
            }
            let grid: Vec<f64> = (0..=((c - a) / 0.01) as usize)
                .map(|i| a + i as f64 * 0.01)
                .collect();
            // Every circle placed by block k that reaches the support's span.
            let placed: Vec<(f64, f64)> = (0..dz.len())
                .filter(|&i| block_of[i] <= k && (dz[i] - z_r).abs() <= R_O + R_S)
                .map(|i| (dz[i], dx[i]))
                .collect();
            let under = stock.eval_many(&grid).unwrap();
            let s: Vec<f64> = grid
                .iter()
                .zip(under)
                .map(|(&g, mut v)| {
                    for &(zc, xc) in &placed {
                        if (g - zc).abs() <= R_S {
                            v = v.min(xc - (R_S * R_S - (g - zc).powi(2)).sqrt());
                        }
                    }
                    v
                })
                .collect();
            let fine = Profile::new(grid, s).unwrap();
            let exact = drop_circle(&fine, z_r, R_O, Side::Outside)
                .unwrap()
                .centre_x;
            let u = t.centre_x[k];
            assert!(
                (u - exact).abs() <= 1e-3,
                "B {b}, block {k}: track {u}, simulation {exact}"
            );
        }
        assert!(t.max_model_difference >= 0.0);
    }
}
