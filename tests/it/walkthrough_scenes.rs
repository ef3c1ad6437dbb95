//! Walkthrough test scenes shared by `walkthrough`, `walkthrough_lod` and
//! `view_cells`, as macros that expand to string literals so each test
//! module can `concat!` its own header in front of them.

/// A GPU whose only cost is triangle setup (split architecture, 10 ns per
/// triangle) and no noise: a frame's time is linear in its triangles by
/// construction.
macro_rules! linear_gpu {
    () => {
        r#"
[gpu]
architecture = "split"
[gpu.geometry]
triangle_setup = "10ns"
[noise]
enabled = false
"#
    };
}
pub(crate) use linear_gpu;

/// No vsync, immediate presentation: frames are not quantized to refreshes.
macro_rules! free_running_display {
    () => {
        r#"
[display]
vsync = false
present_mode = "immediate"
"#
    };
}
pub(crate) use free_running_display;

/// A coarse pos table (4 x 2 x 1 view parameters): quick to build.
macro_rules! coarse_pos {
    () => {
        r#"
[estimation.pos]
alpha_steps = 4
gamma_steps = 2
phi_steps = 1
"#
    };
}
pub(crate) use coarse_pos;

/// A camera walking 120 m along +y past three listed objects: "a" (two
/// levels) beside the path, "b" (textured) behind and to the side, "c" a
/// small 50,000-triangle object ahead.
macro_rules! three_objects_walk {
    () => {
        r#"
[camera]
speed = 150.0
[[camera.keyframes]]
position = [0.0, -60.0, 1.7]
yaw = 90
[[camera.keyframes]]
position = [0.0, 60.0, 1.7]
yaw = 90
[[scene.objects]]
name = "a"
position = [15.0, 0.0, 0.0]
size = [8.0, 8.0, 12.0]
levels = [{ triangles = 3000, acmr = 1.2 }, { triangles = 700, acmr = 1.2 }]
[[scene.objects]]
name = "b"
position = [-20.0, 30.0, 0.0]
size = [10.0, 6.0, 20.0]
levels = [{ triangles = 1200, acmr = 1.2 }]
texture = 1
[[scene.objects]]
name = "c"
position = [12.0, 80.0, 0.0]
size = [4.0, 4.0, 4.0]
levels = [{ triangles = 50000, acmr = 1.2 }]
"#
    };
}
pub(crate) use three_objects_walk;
