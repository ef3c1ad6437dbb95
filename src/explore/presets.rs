//! The page's lessons: each a `--set` list on the default model that shows
//! one thing, with two sentences saying what to look at. `docs/teaching.md`
//! builds its exercises on them, and `tests/it/explore.rs` checks that each
//! shows what its text says.

use serde::Serialize;

/// One lesson.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Preset {
    /// Its name in the URL and the docs.
    pub id: &'static str,
    /// Its title on the page.
    pub title: &'static str,
    /// What it shows and what to do, in two sentences.
    pub text: &'static str,
    /// The assignments it makes (on top of the page's start).
    pub sets: &'static [&'static str],
}

/// The lessons, in the order of `docs/teaching.md`.
pub const PRESETS: &[Preset] = &[
    Preset {
        id: "vsync-quantisation",
        title: "60 -> 30 Hz: vsync quantisation (paper 004)",
        text: "With double-buffered vsync the GPU must wait for the vertical blank before it may draw the next \
               frame, so a frame that needs a little more than one refresh (17.7 ms of GPU work) is shown every \
               33.3 ms, not every 17.7. Drag the fragment cost down until the GPU frame fits in 16.7 ms and watch \
               the frame time fall to one refresh.",
        sets: &[
            "noise.enabled=false",
            "cpu.non_render=\"1ms\"",
            "gpu.fragment.per_fragment=\"12ns\"",
        ],
    },
    Preset {
        id: "table1",
        title: "Geometry and fragment add up (paper 000 Table 1)",
        text: "Within one frame the bottleneck moves between the geometry and the fragment stage, so the GPU's \
               frame time lies between the slower stage and the two added up. Raise the fragment cost and watch \
               the verdict move from geometry to fragment.",
        sets: &[
            "noise.enabled=false",
            "display.vsync=false",
            "cpu.non_render=\"1ms\"",
            "cpu.per_object=\"1us\"",
            "cpu.per_draw=\"1us\"",
            "gpu.geometry.vertex_shader=\"80ns\"",
            "gpu.fragment.per_fragment=\"1ns\"",
        ],
    },
    Preset {
        id: "render-ahead",
        title: "Render-ahead latency",
        text: "When the GPU is the bottleneck the CPU runs ahead and its frames wait in a queue before the GPU, \
               so latency grows by about a GPU frame while the frame rate barely changes. Move the frames the CPU \
               may run ahead from 3 to 1 and compare the latency with the frame time.",
        sets: &[
            "noise.enabled=false",
            "display.vsync=false",
            "cpu.non_render=\"1ms\"",
            "gpu.fragment.per_fragment=\"10ns\"",
            "cpu.max_frames_ahead=3",
        ],
    },
    Preset {
        id: "triple-buffering",
        title: "Triple buffering",
        text: "A 20 ms GPU frame on a 60 Hz double-buffered display waits for every second vertical blank, so \
               frames come 33.3 ms apart. A third buffer lets the GPU start the next frame at once: the display \
               interval falls toward 20 ms, mixing one and two refreshes.",
        sets: &[
            "noise.enabled=false",
            "cpu.non_render=\"1ms\"",
            "gpu.fragment.per_fragment=\"14ns\"",
            "display.buffers=3",
        ],
    },
    Preset {
        id: "limiter-place",
        title: "A frame limiter before or after input",
        text: "A 40 fps limiter that waits before the frame starts holds the input sample too, so the frame is \
               shown soon after it samples input. Switch where the limiter waits to present and the wait lands \
               between input and screen: same frame rate, more latency.",
        sets: &[
            "noise.enabled=false",
            "display.vsync=false",
            "pacing.limit=\"40Hz\"",
            "pacing.limit_from=\"start\"",
        ],
    },
    Preset {
        id: "vrr-lfc",
        title: "VRR with low-framerate compensation",
        text: "On a 48-144 Hz variable-refresh panel each frame is shown as soon as it is done, without waiting \
               for a fixed vertical blank. Below 48 fps the panel shows the old frame again (a repeated refresh), \
               and a frame that arrives during that repeat waits for it.",
        sets: &[
            "noise.enabled=false",
            "display.refresh=\"144Hz\"",
            "display.vrr.min_refresh=\"48Hz\"",
            "cpu.non_render=\"25ms\"",
        ],
    },
    Preset {
        id: "frame-generation",
        title: "Frame generation's latency",
        text: "Frame generation shows an interpolated frame between two rendered ones, so twice as many frames \
               reach the screen. The newer rendered frame must be held back half a frame to show the generated \
               one first, so latency rises by that hold-back plus the interpolation's cost.",
        sets: &[
            "noise.enabled=false",
            "display.vsync=false",
            "display.buffers=3",
            "cpu.non_render=\"1ms\"",
            "gpu.fragment.per_fragment=\"10ns\"",
            "frame_generation.enabled=true",
        ],
    },
];
