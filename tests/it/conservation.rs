//! Property tests over random models: time is conserved exactly in
//! picoseconds (CPU busy + wait, GPU busy + idle, every unit's states, the
//! bottleneck shares), every command issued is executed once, each frame's
//! timeline is ordered, every frame ends displayed or dropped, and no output
//! is NaN.

use crate::common;
use common::{null_paths, try_run};
use proptest::prelude::*;

#[derive(Debug, Clone)]
struct Params {
    scene: bool,
    fidelity: &'static str,
    cpu_us: u64,
    gpu_us: u64,
    fifo: u64,
    bytes: bool,
    depth: u32,
    buffers: u32,
    mode: &'static str,
    vsync: bool,
    ahead: u32,
    noise: bool,
    gpu_noise: bool,
    groups: u64,
    grid: u32,
    seed: u64,
    /// A frame limiter's place (`None`: no `[pacing]`).
    pacing: Option<&'static str>,
}

fn params() -> impl Strategy<Value = Params> {
    (
        (
            any::<bool>(),
            prop_oneof![Just("triangle"), Just("draw")],
            0u64..20_000,
            0u64..20_000,
            0u64..6,
            any::<bool>(),
            0u32..6,
        ),
        (
            2u32..5,
            prop_oneof![Just("fifo"), Just("mailbox"), Just("immediate")],
            any::<bool>(),
            1u32..5,
            any::<bool>(),
            any::<bool>(),
        ),
        (
            1u64..5,
            1u32..12,
            0u64..i64::MAX as u64,
            prop_oneof![
                Just(None),
                Just(Some("start")),
                Just(Some("present")),
                Just(Some("submit"))
            ],
        ),
    )
        .prop_map(
            |(
                (scene, fidelity, cpu_us, gpu_us, fifo, bytes, depth),
                (buffers, mode, vsync, ahead, noise, gpu_noise),
                (groups, grid, seed, pacing),
            )| Params {
                scene,
                fidelity,
                cpu_us,
                gpu_us,
                fifo,
                bytes,
                depth,
                buffers,
                mode,
                vsync,
                ahead,
                noise,
                gpu_noise,
                groups,
                grid,
                seed,
                pacing,
            },
        )
}

fn model(p: &Params) -> String {
    let workload = if p.scene {
        format!(
            r#"[workload]
kind = "scene"
depth_complexity = 2.0
[[workload.groups]]
name = "a"
count = {}
mesh = "grid:{}x{}"
textures = 2
triangle_pixels = {{ kind = "lognormal", median = 20.0, sigma = 1.0 }}
geometry_upload = 1000
[[workload.groups]]
name = "b"
count = 2
mesh = {{ triangles = 300, acmr = 1.5 }}
shaders = 2
triangle_pixels = {{ kind = "exponential", mean = 5.0 }}
"#,
            p.groups, p.grid, p.grid
        )
    } else {
        format!(
            "[workload]\nkind = \"fixed\"\ncpu = {{ kind = \"uniform\", min = \"0ms\", max = \"{}us\" }}\ngpu = \"{}us\"\n",
            p.cpu_us, p.gpu_us
        )
    };
    format!(
        r#"fidelity = "{fid}"
[run]
frames = 12
seed = {seed}
[cpu]
input_sampling = "0.1ms"
non_render = {{ kind = "exponential", mean = "{cpu}us" }}
per_draw = "20us"
swap = "10us"
max_frames_ahead = {ahead}
[cpu.state_change]
texture = "30us"
shader = "50us"
[command_fifo]
capacity = {fifo}
unit = "{unit}"
[gpu]
command = "1us"
clear = "50us"
swap = "5us"
[gpu.geometry]
vertex_shader = "30ns"
index_fetch = "1ns"
[gpu.fragment]
fifo_depth = {depth}
per_fragment = "3ns"
per_rejected_fragment = "1ns"
[display]
refresh = "120Hz"
vsync = {vsync}
buffers = {buffers}
present_mode = "{mode}"
[noise]
enabled = {noise}
[[noise.periodic]]
name = "tick"
target = "cpu"
period = "3ms"
jitter = "1ms"
duration = "0.4ms"
[[noise.random]]
name = "driver"
target = "{target}"
rate = "300Hz"
duration = {{ kind = "pareto", scale = "20us", shape = 2.5 }}
{workload}{pacing}"#,
        pacing = p.pacing.map_or(String::new(), |place| format!(
            "[pacing]\nlimit = \"150Hz\"\nlimit_from = \"{place}\"\n"
        )),
        fid = p.fidelity,
        seed = p.seed,
        cpu = p.cpu_us,
        ahead = p.ahead,
        fifo = if p.bytes { p.fifo * 40 } else { p.fifo },
        unit = if p.bytes { "bytes" } else { "entries" },
        depth = p.depth,
        vsync = p.vsync,
        buffers = p.buffers,
        mode = p.mode,
        noise = p.noise,
        target = if p.gpu_noise { "gpu" } else { "cpu" },
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, .. ProptestConfig::default() })]

    #[test]
    fn time_and_commands_are_conserved(p in params()) {
        let r = try_run(&model(&p), &[]).map_err(TestCaseError::fail)?;
        let c = &r.clocks;
        let e = c.elapsed;
        prop_assert_eq!(c.cpu.iter().sum::<u64>(), e);
        prop_assert_eq!(c.front.iter().sum::<u64>(), e);
        prop_assert_eq!(c.geometry.iter().sum::<u64>(), e);
        prop_assert_eq!(c.fragment.iter().sum::<u64>(), e);
        prop_assert_eq!(c.gpu[0] + c.gpu[1], e);
        prop_assert_eq!(c.bottleneck.iter().sum::<u64>(), e);
        // GPU busy is the union of its units' busy time: at least each one.
        prop_assert!(c.gpu[0] >= c.geometry[0].max(c.fragment[0]).max(c.front[0]));
        // Every command issued is executed exactly once.
        prop_assert_eq!(r.commands.0, r.commands.1);
        if p.scene {
            // clear + swap + at least a draw per object.
            prop_assert!(r.commands.0 >= 12 * (2 + p.groups + 2));
        } else {
            prop_assert_eq!(r.commands.0, 12 * 3, "clear, fixed work, swap per frame");
        }
        // Per frame: busy + wait = frame time, exactly; the timeline is ordered.
        prop_assert_eq!(r.records.len(), 12);
        // A limiter's wait before a frame belongs to no frame (the frame
        // starts when it ends): over the run, every CPU picosecond from the
        // first start to the last present is a frame's or that wait's.
        let first_to_last = r.records.last().unwrap().present.0 - r.records[0].start.0;
        let framed: u64 = r.records.iter().map(|f| f.cpu_busy + f.cpu_wait).sum();
        prop_assert_eq!(framed + c.cpu[5], first_to_last);
        for (i, f) in r.records.iter().enumerate() {
            let end = r.records.get(i + 1).map(|n| n.start).unwrap_or(f.present);
            if p.pacing != Some("start") {
                prop_assert_eq!(f.cpu_busy + f.cpu_wait, end.0 - f.start.0, "frame {}", i);
            }
            prop_assert!(f.start <= f.input && f.input <= f.present);
            let (gs, ge) = (f.gpu_start.unwrap(), f.gpu_end.unwrap());
            prop_assert!(f.input <= gs && gs <= ge);
            prop_assert!(f.gpu_busy <= ge.0 - gs.0);
            prop_assert!(f.displayed.is_some() != f.dropped, "frame {} displayed {:?} dropped {}", i, f.displayed, f.dropped);
            if let Some(d) = f.displayed { prop_assert!(d >= ge); }
            if i > 0 { prop_assert!(f.start >= r.records[i - 1].present); }
        }
        // Frames appear in order.
        let shown: Vec<_> = r.records.iter().filter_map(|f| f.displayed).collect();
        prop_assert!(shown.windows(2).all(|w| w[0] <= w[1]));
        let mut nulls = vec![];
        null_paths(&r.summary(), "", &mut nulls);
        prop_assert!(nulls.is_empty(), "NaN/null in summary: {:?}", nulls);
    }
}
