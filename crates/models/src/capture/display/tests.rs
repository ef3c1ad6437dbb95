use super::*;
use crate::capture::presentmon::Capture;

/// A capture of the given swap chains (PresentMon 1 columns): each row is
/// (application, address, mode, sync interval, tearing, present ms,
/// ms until displayed or None).
type Row<'a> = (&'a str, &'a str, &'a str, i64, u8, f64, Option<f64>);

fn capture(rows: &[Row<'_>]) -> Capture {
    let mut s = String::from(
        "Application,ProcessID,SwapChainAddress,Runtime,SyncInterval,AllowsTearing,PresentMode,Dropped,TimeInSeconds,MsBetweenPresents,MsInPresentAPI,MsUntilRenderComplete,MsUntilDisplayed\n",
    );
    for (app, sc, mode, sync, tear, t, until) in rows {
        let (dropped, u) = match until {
            Some(u) => (0, *u),
            None => (1, 0.0),
        };
        s += &format!(
            "{app},1,{sc},DXGI,{sync},{tear},{mode},{dropped},{},5.0,0.2,1.0,{u}\n",
            t / 1e3
        );
    }
    Capture::parse("t.csv", s.as_bytes()).unwrap()
}

const P120: f64 = 1000.0 / 120.0;
const P60: f64 = 1000.0 / 60.0;

/// A swap chain's rows shown at the given refresh counts of `period` (a
/// present 3 ms before each).
fn shown<'a>(
    app: &'a str,
    sc: &'a str,
    mode: &'a str,
    sync: i64,
    counts: &[u32],
    period: f64,
    phase: f64,
) -> Vec<Row<'a>> {
    counts
        .iter()
        .map(|&k| {
            let screen = phase + period * f64::from(k);
            (app, sc, mode, sync, 0, screen - 3.0, Some(3.0))
        })
        .collect()
}

fn target(c: &Capture, app: &str) -> DisplayInference {
    let p = c.presents.iter().find(|p| &*p.application == app).unwrap();
    infer_display(c, p)
}

#[test]
fn an_app_showing_every_fourth_refresh_fits_the_panel_once_one_change_is_three() {
    // Cyberpunk 2077 capped at 30 fps on a 120 Hz panel: 33.3 ms between
    // display changes, once 25 ms: the panel's 8.33 ms, not 30 Hz.
    let mut counts = vec![0u32];
    for i in 1..200 {
        counts.push(counts[i - 1] + if i % 50 == 0 { 3 } else { 4 });
    }
    let c = capture(&shown("game.exe", "0x1", "Composed: Flip", 0, &counts, P120, 5.0));
    let d = target(&c, "game.exe");
    let r = d.refresh.unwrap();
    assert!((r.hz - 120.0).abs() < 1e-6, "{}", r.hz);
    assert_eq!(r.from, RefreshEvidence::DisplayChanges);
    assert_eq!(r.ambiguous_below_hz, None);
    assert_eq!(d.flips, Flips::OnGrid);
    assert!(r.grid.holds(5.0 + 1000.0), "the phase: {}", r.grid.phase_ms);
}

#[test]
fn the_compositor_s_presents_give_the_rate_an_app_s_own_frames_cannot() {
    // A game at 30 fps on a 120 Hz panel, every change four refreshes
    // apart, beside dwm.exe flipping at most refreshes.
    let game: Vec<u32> = (0..100).map(|i| 4 * i).collect();
    let dwm: Vec<u32> = (0..400).filter(|k| k % 7 != 3).collect();
    let mut rows = shown("game.exe", "0x1", "Composed: Flip", 0, &game, P120, 2.0);
    rows.extend(shown("dwm.exe", "0x2", "Hardware: Legacy Flip", 1, &dwm, P120, 2.0));
    rows.sort_by(|a, b| a.5.total_cmp(&b.5));
    let c = capture(&rows);
    let d = target(&c, "game.exe");
    let r = d.refresh.unwrap();
    assert!((r.hz - 120.0).abs() < 1e-6, "{}", r.hz);
    assert_eq!(r.from, RefreshEvidence::Compositor);
    assert_eq!(d.monitors, 1);
    assert!(r.chains.iter().any(|c| c.starts_with("dwm.exe")), "{:?}", r.chains);
    // Without dwm.exe the game alone fits 30 Hz: below any panel, so the
    // slowest multiple at or above 48 Hz is taken, and said to be ambiguous.
    let c = capture(&shown("game.exe", "0x1", "Composed: Flip", 0, &game, P120, 2.0));
    let r = target(&c, "game.exe").refresh.unwrap();
    assert!((r.hz - 60.0).abs() < 1e-6, "{}", r.hz);
    assert!((r.ambiguous_below_hz.unwrap() - 30.0).abs() < 1e-6);
}

#[test]
fn two_monitors_each_with_its_compositor_swap_chain_and_the_app_on_its_own() {
    let p144 = 1000.0 / 144.0;
    let mut rows = shown(
        "dwm.exe",
        "0xA",
        "Hardware: Legacy Flip",
        1,
        &(0..300).collect::<Vec<_>>(),
        P60,
        1.0,
    );
    rows.extend(shown(
        "dwm.exe",
        "0xB",
        "Hardware: Legacy Flip",
        1,
        &(0..700).collect::<Vec<_>>(),
        p144,
        3.3,
    ));
    let game: Vec<u32> = (0..300).map(|i| 2 * i + u32::from(i % 3 == 0)).collect();
    rows.extend(shown("game.exe", "0x1", "Composed: Flip", 1, &game, p144, 3.3));
    rows.sort_by(|a, b| a.5.total_cmp(&b.5));
    let c = capture(&rows);
    let d = target(&c, "game.exe");
    assert_eq!(d.monitors, 2);
    let r = d.refresh.unwrap();
    assert!((r.hz - 144.0).abs() < 1e-6, "{}", r.hz);
    assert!(r.chains.iter().any(|c| c == "dwm.exe 0xB"), "{:?}", r.chains);
    assert!(!r.chains.iter().any(|c| c == "dwm.exe 0xA"), "{:?}", r.chains);
}

/// A game's composed frames at the given refresh counts of 120 Hz, then
/// 400 independent flips at sync interval 0 from `t0` ms, the i-th at
/// `at(i)` after it (`tearing`: whether they may tear).
fn composed_then_flips(counts: &[u32], t0: f64, at: &dyn Fn(f64) -> f64, tearing: u8) -> Capture {
    let mut rows = shown("game.exe", "0x1", "Composed: Flip", 0, counts, P120, 0.7);
    for i in 0..400 {
        let screen = t0 + at(f64::from(i));
        rows.push((
            "game.exe",
            "0x1",
            "Hardware Composed: Independent Flip",
            0,
            tearing,
            screen - 4.0,
            Some(4.0),
        ));
    }
    capture(&rows)
}

#[test]
fn unsynced_flips_off_the_grid_are_a_variable_refresh_and_flips_that_may_tear_tear() {
    // Composed frames on a 120 Hz grid, then independent flips at sync
    // interval 0 every 8.6 ms (116 fps): no fixed refresh shows them so.
    let every: Vec<u32> = (0..60).collect();
    let t0 = 0.7 + 60.0 * P120;
    let c = composed_then_flips(&every, t0, &|i| 8.6 * i + 0.25 * (i % 2.0), 0);
    let d = target(&c, "game.exe");
    assert_eq!(d.flips, Flips::VariableRefresh);
    let v = d.vrr.unwrap();
    assert!((v.max_hz - 120.0).abs() < 1e-6 && v.max_from_refresh, "{v:?}");
    assert_eq!(v.min_hz, ASSUMED_VRR_MIN_HZ);
    // Their changes never come faster than the panel allows; a 60 Hz
    // grid (composed frames every second refresh) is raised to 120 Hz
    // by flips 16 ms apart.
    let second: Vec<u32> = (0..60).map(|i| 2 * i).collect();
    let t1 = 0.7 + 120.0 * P120;
    let d = target(
        &composed_then_flips(&second, t1, &|i| 16.0 * i + 1.1 * (i % 3.0), 0),
        "game.exe",
    );
    assert_eq!(d.flips, Flips::VariableRefresh);
    let r = d.refresh.unwrap();
    assert!(
        (r.hz - 120.0).abs() < 1e-6 && (r.raised_from_hz.unwrap() - 60.0).abs() < 1e-6,
        "{r:?}"
    );
    // Flips that may tear are shown when ready, whatever the grid.
    let d = target(&composed_then_flips(&every, t1, &|i| 7.1 * i, 1), "game.exe");
    assert_eq!(d.flips, Flips::Tearing);
    assert!((d.refresh.unwrap().hz - 120.0).abs() < 1e-6);
}

#[test]
fn nothing_on_a_grid_infers_no_refresh() {
    // A tearing swap chain alone: its changes follow the GPU.
    let rows: Vec<Row<'_>> = (0..300)
        .map(|i| {
            let s = 10.0 + 9.7 * f64::from(i) + 2.3 * (f64::from(i) * 0.618).fract();
            (
                "game.exe",
                "0x1",
                "Hardware: Independent Flip",
                0,
                1,
                s - 2.0,
                Some(2.0),
            )
        })
        .collect();
    let d = target(&capture(&rows), "game.exe");
    assert!(d.refresh.is_none());
    assert_eq!(d.flips, Flips::Tearing);
    assert_eq!(d.chains[0].path, Path::FlipTearing);
}

#[test]
fn a_few_changes_off_the_grid_do_not_make_a_finer_one() {
    // 60 Hz with four changes off by 1.5-2.4 ms (test_case_0's dwm.exe):
    // a period of a seventh fits two of them by chance, not enough.
    let mut t: Vec<f64> = (0..190).map(|k| 3.0 + P60 * f64::from(k)).collect();
    for (i, off) in [(20, 1.6), (60, -2.4), (100, 1.62), (150, 2.43)] {
        t[i] += off;
    }
    let g = fit_grid(&t).unwrap();
    assert!((g.hz() - 60.0).abs() < 1e-3, "{}", g.hz());
    assert!(g.on_grid + 8 >= g.intervals, "{g:?}");
    // Fewer than three intervals: no grid.
    assert!(fit_grid(&[1.0, 17.0, 33.7]).is_none());
    assert!(fit_grid(&[]).is_none());
}

#[test]
fn the_grid_recovers_period_and_phase_from_skipped_refreshes() {
    let p = 16.683;
    let screen: Vec<f64> = [0u32, 1, 2, 4, 5, 8, 9, 10, 13]
        .iter()
        .map(|&k| 3.2 + p * f64::from(k))
        .collect();
    let g = fit_grid(&screen).unwrap();
    assert!((g.period_ms - p).abs() < 1e-9, "{g:?}");
    assert!(g.holds(3.2) && g.holds(3.2 + 100.0 * p), "{g:?}");
    assert_eq!((g.on_grid, g.intervals), (8, 8));
}

#[test]
fn a_grid_below_any_panel_takes_the_multiple_its_blank_changes_fit() {
    let p = 1000.0 / 30.0;
    // A 30 fps game's changes alone: the slowest multiple at or above 48 Hz.
    assert_eq!(panel_multiple(p, &[33.33, 33.34, 33.32, 66.67]), 2.0);
    // A few composed frames 16.7 and 25 ms apart: 25 ms is three refreshes
    // of 120 Hz and one and a half of 60 Hz; an outlier that fits no panel
    // (64.76 ms) does not stop it.
    assert_eq!(panel_multiple(p, &[33.33, 33.34, 16.71, 24.94, 64.76, 33.3]), 4.0);
    // A stray interval (a hitch) that no panel's grid fits changes nothing.
    // (One that a finer panel's grid fits by chance would: the evidence
    // is a single interval, as in Alan Wake 2's capture under the driver's
    // 30 fps cap.)
    assert_eq!(panel_multiple(p, &[33.33, 33.34, 41.3, 33.3]), 2.0);
    // Nothing to go on.
    assert_eq!(panel_multiple(p, &[]), 2.0);
}
