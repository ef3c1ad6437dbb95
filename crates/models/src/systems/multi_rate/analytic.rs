//! Closed forms of paper 003 §3.2: the hand analysis, which assumes an event
//! arrives at a frame start, and the bounds over all phases that the event
//! simulation must stay within.
//!
//! Paper (all at 1280x1024, 8 B/pixel, tracker 20 ms / 40 ms):
//! - conventional: `L + R_sc` = 40 + 166 = 206 ms; worst adds one tracker
//!   period (226 ms);
//! - fast client: `L + T_draw + T_render` = 40 + 10 + 23 = 73 ms;
//! - slow client (cluster): `L + R_sc + T_read + T_send` = 40 + 166 + 20 +
//!   111 = 337 ms; worst adds one tracker period and one FC frame: 390 ms;
//! - slow client (multi-GPU, zero copy): 40 + 166 + 20 (+ 0.1 lock) = 226 ms;
//!   worst 279 ms.
//!
//! Reading: the paper's 337 says "and uploading it to FC's graphics card",
//! but its sum has no upload term; the FC frame (33 ms) appears only in the
//! worst case. We keep the paper's arithmetic for `best`/`worst` and give
//! the physically reachable bounds separately (`phase_min`/`phase_max`):
//! an image is visible only when the FC frame that uploaded it has ended,
//! and an event can wait almost a whole client frame for that frame to
//! start. The paper gives no worst case for FC; we apply its own slow-client
//! rule (one tracker period plus one FC frame): 73 + 20 + 33 = 126 ms.
//!
//! Where the closed forms hold: the slow path's `worst`, `phase_max` and
//! `phase_mean` assume the link carries SC's images as fast as SC makes
//! them (`T_send <= SC interval`, [`Analytic::link_keeps_up`]). When it does
//! not (a stereo image over Gigabit Ethernet: 222 ms against 206 ms), the
//! link sends back to back and a buffer read back while a send is in
//! progress waits up to one more `T_send`; newer buffers replacing it carry
//! the event too, so the event still leaves on the next send. The bound that
//! holds for any link is `phase_max + T_send` ([`Bounds::bound_max`]);
//! [`Bounds::holds`] says whether the closed forms' assumptions hold, and
//! [`Analytic::caveats`] says in words what fails.

use serde::Serialize;

use crate::engine::Duration;

use super::config::{MultiRateConfig, TransferPath};

/// Every per-frame term, from the model.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Terms {
    /// Tracker period `P`.
    pub tracker_period: Duration,
    /// Sensor-to-client latency `L`.
    pub sensor_latency: Duration,
    /// SC render `R_sc`.
    pub sc_render: Duration,
    /// SC read-back `T_read`.
    pub sc_readback: Duration,
    /// SC -> FC transfer `T_send` on the chosen path.
    pub transfer: Duration,
    /// FC upload `T_draw`.
    pub fc_upload: Duration,
    /// FC render `T_render` (plus deferred shading when enabled).
    pub fc_render: Duration,
    /// Conventional client frame.
    pub conventional_frame: Duration,
    /// Display latency.
    pub display: Duration,
    /// SC's frame-rate cap (its period), if any.
    pub sc_period: Option<Duration>,
    /// FC's frame-rate cap (its period), if any.
    pub fc_period: Option<Duration>,
}

impl Terms {
    /// The terms of a model.
    pub fn of(cfg: &MultiRateConfig) -> Terms {
        let bytes = cfg.frame_bytes();
        Terms {
            tracker_period: cfg.tracker.period,
            sensor_latency: cfg.tracker.latency,
            sc_render: cfg.slow_client.render,
            sc_readback: cfg.slow_client.readback.transfer_time(bytes),
            transfer: transfer_time(cfg, bytes),
            fc_upload: cfg.fast_client.upload.transfer_time(bytes),
            fc_render: Duration(cfg.fast_client.render.0.saturating_add(cfg.deferred_shading().0)),
            conventional_frame: cfg.conventional.frame.unwrap_or(cfg.slow_client.render),
            display: cfg.display.latency,
            sc_period: cfg.slow_client.rate.as_ref().map(|r| r.period),
            fc_period: cfg.fast_client.rate.as_ref().map(|r| r.period),
        }
    }

    /// SC's frame interval: its frame time, rounded up to whole periods of
    /// its rate cap.
    pub fn sc_interval(&self) -> Duration {
        capped(self.sc_frame(), self.sc_period)
    }

    /// FC's frame interval: its frame time, rounded up to whole periods of
    /// its rate cap (20 Hz caps a 33 ms frame to one every 50 ms).
    pub fn fc_interval(&self) -> Duration {
        capped(self.fc_frame(), self.fc_period)
    }

    /// SC frame time `R_sc + T_read`.
    pub fn sc_frame(&self) -> Duration {
        Duration(self.sc_render.0.saturating_add(self.sc_readback.0))
    }

    /// FC frame time `T_draw + T_render`.
    pub fn fc_frame(&self) -> Duration {
        Duration(self.fc_upload.0.saturating_add(self.fc_render.0))
    }
}

/// `frame` rounded up to a whole number of `period`s (unchanged without one).
pub fn capped(frame: Duration, period: Option<Duration>) -> Duration {
    match period {
        Some(p) if p.0 > 0 => Duration(frame.0.div_ceil(p.0).max(1).saturating_mul(p.0)),
        _ => frame,
    }
}

/// Time to move `bytes` over the model's transfer path.
pub fn transfer_time(cfg: &MultiRateConfig, bytes: u64) -> Duration {
    match cfg.transfer.path {
        TransferPath::Network => cfg.network.bandwidth.transfer_time(bytes),
        TransferPath::Loopback => cfg.loopback.bandwidth.transfer_time(bytes),
        TransferPath::SharedCopy => cfg.shared_copy.bandwidth.transfer_time(bytes),
        TransferPath::ZeroCopy => cfg.zero_copy.lock,
    }
}

/// Latency bounds of one path, milliseconds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Bounds {
    /// The paper's case: the event arrives at a frame start.
    pub best: f64,
    /// The paper's worst case.
    pub worst: f64,
    /// Smallest latency any phase can give.
    pub phase_min: f64,
    /// Largest latency any phase can give (while the link keeps up).
    pub phase_max: f64,
    /// Mean over independent uniform phases.
    pub phase_mean: f64,
    /// Whether the assumptions of `worst`, `phase_max` and `phase_mean`
    /// hold for this model (the slow path: the link keeps up with SC).
    /// When false, those three are not bounds of the simulated latency.
    pub holds: bool,
    /// The largest latency any phase can give whether or not the
    /// assumptions hold: `phase_max` when they do; on a slow path whose link
    /// does not keep up, `phase_max + T_send` (see the module
    /// documentation).
    pub bound_max: f64,
}

fn ms(ps: u64) -> f64 {
    ps as f64 / 1e9
}

/// Closed forms for the fast, slow and conventional paths.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Analytic {
    /// Input visible through FC.
    pub fast: Bounds,
    /// Input visible through SC's image on FC.
    pub slow: Bounds,
    /// Input visible on a conventional single client.
    pub conventional: Bounds,
    /// Whether the link keeps up with SC (`T_send <= T_sc`); if not,
    /// buffers wait and are replaced, and `slow.phase_max` does not hold.
    pub link_keeps_up: bool,
}

/// The closed forms of a model.
pub fn analytic(t: &Terms) -> Analytic {
    let p = t.tracker_period.0;
    let l = t.sensor_latency.0;
    let d = t.display.0;
    let fc = t.fc_frame().0;
    let sc = t.sc_frame().0;
    // Frame intervals: the frame times unless a rate cap stretches them.
    let fi = t.fc_interval().0;
    let si = t.sc_interval().0;
    let x = t.transfer.0;
    let cv = t.conventional_frame.0;
    let half = |v: u64| v as f64 / 2.0;
    let keeps_up = x <= si;
    let slow_max = p + l + si + sc + x + fi + fc + d;
    let fast_best = l + fc;
    let slow_best = l + sc + x;
    let conv_best = l + cv;
    Analytic {
        fast: Bounds {
            best: ms(fast_best + d),
            worst: ms(fast_best + p + fi + d),
            phase_min: ms(l + fc + d),
            phase_max: ms(p + l + fi + fc + d),
            phase_mean: (half(p) + (l + fc + d) as f64 + half(fi)) / 1e9,
            holds: true,
            bound_max: ms(p + l + fi + fc + d),
        },
        slow: Bounds {
            best: ms(slow_best + d),
            worst: ms(slow_best + p + fi + d),
            phase_min: ms(slow_best + fc + d),
            phase_max: ms(slow_max),
            phase_mean: (half(p) + (slow_best + fc + d) as f64 + half(si) + half(fi)) / 1e9,
            holds: keeps_up,
            bound_max: ms(if keeps_up { slow_max } else { slow_max + x }),
        },
        conventional: Bounds {
            best: ms(conv_best + d),
            worst: ms(conv_best + p + d),
            phase_min: ms(conv_best + d),
            phase_max: ms(p + l + 2 * cv + d),
            phase_mean: (half(p) + (conv_best + d) as f64 + half(cv)) / 1e9,
            holds: true,
            bound_max: ms(p + l + 2 * cv + d),
        },
        link_keeps_up: keeps_up,
    }
}

impl Analytic {
    /// One sentence per path whose closed forms do not hold, saying why and
    /// which bound holds instead (empty when every closed form holds).
    pub fn caveats(&self, t: &Terms) -> Vec<String> {
        let mut out = Vec::new();
        if !self.slow.holds {
            out.push(format!(
                "slow path: the link does not keep up with SC (T_send {:.1} ms > SC frame interval {:.1} ms), \
                 so buffers wait for the link; the closed forms assume they do not: worst {:.1}, phase_max {:.1} \
                 and phase_mean {:.1} ms do not hold; the bound that holds is max <= {:.1} ms \
                 (phase_max + one T_send, the send in progress)",
                t.transfer.as_ms_f64(),
                t.sc_interval().as_ms_f64(),
                self.slow.worst,
                self.slow.phase_max,
                self.slow.phase_mean,
                self.slow.bound_max
            ));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cfg(text: &str) -> MultiRateConfig {
        let t: toml::Table = toml::from_str(text).unwrap();
        t.try_into().unwrap()
    }

    #[test]
    fn paper_cluster_numbers() {
        let a = analytic(&Terms::of(&cfg("system = \"multi_rate\"")));
        assert!((a.conventional.best - 206.0).abs() < 1e-9);
        assert!((a.conventional.worst - 226.0).abs() < 1e-9);
        assert!((a.fast.best - 73.0).abs() < 1e-9);
        // 40 + 166 + 20 + 111.1 (10 MiB at 90 MiB/s)
        assert!((a.slow.best - 337.0).abs() < 0.2, "{}", a.slow.best);
        assert!((a.slow.worst - 390.0).abs() < 0.2, "{}", a.slow.worst);
        assert!(a.link_keeps_up);
        assert!(a.slow.holds && a.slow.bound_max == a.slow.phase_max);
        assert!(a.caveats(&Terms::of(&cfg("system = \"multi_rate\""))).is_empty());
    }

    #[test]
    fn a_link_slower_than_sc_is_flagged_with_the_bound_that_holds() {
        // Stereo over Gigabit Ethernet: 20 MiB in 222.2 ms, SC 166 + 40 ms.
        let t = Terms::of(&cfg("system = \"multi_rate\"\nstereo = true"));
        let a = analytic(&t);
        assert!(!a.link_keeps_up && !a.slow.holds);
        assert!(a.fast.holds && a.conventional.holds);
        let x = t.transfer.as_ms_f64();
        assert!((a.slow.bound_max - (a.slow.phase_max + x)).abs() < 1e-9);
        let c = a.caveats(&t);
        assert_eq!(c.len(), 1);
        assert!(
            c[0].contains("does not keep up") && c[0].contains(&format!("{:.1}", a.slow.bound_max)),
            "{c:?}"
        );
    }

    #[test]
    fn paper_multi_gpu_numbers() {
        let a = analytic(&Terms::of(&cfg(
            "system = \"multi_rate\"\n[transfer]\npath = \"zero_copy\"",
        )));
        assert!((a.slow.best - 226.0).abs() <= 0.1 + 1e-9, "{}", a.slow.best);
        assert!((a.slow.worst - 279.0).abs() <= 0.1 + 1e-9, "{}", a.slow.worst);
        assert!((a.fast.best - 73.0).abs() < 1e-9);
    }

    #[test]
    fn table2_network_transfer_times() {
        // Paper: 66 / 111 / 166 ms for 6 / 10 / 15 MB. 1600x1200x8 B is
        // 14.65 MiB, which the paper rounds to 15 MB: 162.8 ms exact.
        for (res, paper, tol) in [
            ([1024, 768], 66.0, 1.0),
            ([1280, 1024], 111.0, 0.2),
            ([1600, 1200], 166.0, 4.0),
        ] {
            let mut c = cfg("system = \"multi_rate\"");
            c.resolution = res;
            let t = Terms::of(&c).transfer.as_ms_f64();
            assert!((t - paper).abs() < tol, "{res:?}: {t} vs {paper}");
        }
    }

    #[test]
    fn deferred_shading_buffers_and_cost() {
        let c = cfg("system = \"multi_rate\"\n[deferred]\nenabled = true");
        // 144 bits per pixel: 18 bytes, 2.25 times the 64-bit colour+depth.
        assert_eq!(c.frame_bytes(), 1280 * 1024 * 18);
        let wide = cfg("system = \"multi_rate\"\n[deferred]\nenabled = true\nnormal_bits = 96");
        assert_eq!(wide.frame_bytes(), 1280 * 1024 * 24);
        let idx = cfg("system = \"multi_rate\"\n[deferred]\nenabled = true\nmaterials = \"indices\"");
        assert_eq!(idx.frame_bytes(), 1280 * 1024 * 12);
        // Figure 8: four lights at 1600x1200 stereo in about 6 ms on FC.
        let fig8 = cfg("system = \"multi_rate\"\nresolution = [1600, 1200]\nstereo = true\n[deferred]\nenabled = true");
        let shading = fig8.deferred_shading().as_ms_f64();
        assert!((shading - 6.0).abs() < 0.05, "{shading}");
        let t = Terms::of(&fig8);
        assert_eq!(t.fc_render.0, Duration::ms(23).0 + fig8.deferred_shading().0);
    }

    #[test]
    fn rate_caps_stretch_the_frame_interval() {
        // Unset: the paper's numbers.
        let free = analytic(&Terms::of(&cfg("system = \"multi_rate\"")));
        // FC capped at 20 Hz: its 33 ms frame starts every 50 ms.
        let c = cfg("system = \"multi_rate\"\n[fast_client]\nrate = \"20Hz\"");
        let t = Terms::of(&c);
        assert_eq!(t.fc_interval(), Duration::ms(50));
        assert_eq!(t.fc_frame(), Duration::ms(33));
        let a = analytic(&t);
        assert!((a.fast.best - 73.0).abs() < 1e-9);
        // Waiting for the next frame start: up to 50 ms instead of 33, 25 on average instead of 16.5.
        assert!(
            (a.fast.phase_max - (free.fast.phase_max + 17.0)).abs() < 1e-6,
            "{:?}",
            a.fast
        );
        assert!(
            (a.fast.phase_mean - (free.fast.phase_mean + 8.5)).abs() < 1e-6,
            "{:?}",
            a.fast
        );
        assert!((a.fast.worst - (73.0 + 20.0 + 50.0)).abs() < 1e-9);
        // Ticks quantize: at 60 Hz a 33 ms frame waits for the second tick (33.33 ms);
        // a 200 ms SC cap gives 200 ms frames.
        let fast_cap = Terms::of(&cfg("system = \"multi_rate\"\n[fast_client]\nrate = \"60Hz\""));
        assert_eq!(fast_cap.fc_interval().0, 2 * fast_cap.fc_period.unwrap().0);
        let sc = Terms::of(&cfg("system = \"multi_rate\"\n[slow_client]\nrate = \"200ms\""));
        assert_eq!(sc.sc_interval(), Duration::ms(200));
        assert_eq!(capped(Duration::ms(186), Some(Duration::ms(100))), Duration::ms(200));
    }

    #[test]
    fn stereo_doubles_every_buffer_term() {
        let mono = Terms::of(&cfg("system = \"multi_rate\""));
        let stereo = Terms::of(&cfg("system = \"multi_rate\"\nstereo = true"));
        for (m, s) in [
            (mono.transfer, stereo.transfer),
            (mono.sc_readback, stereo.sc_readback),
            (mono.fc_upload, stereo.fc_upload),
        ] {
            assert!(s.0.abs_diff(2 * m.0) <= 1, "{m:?} {s:?}");
        }
        assert_eq!(mono.sc_render, stereo.sc_render);
    }
}
