//! The camera path: one pose per frame, one frame per display refresh (a
//! recorded path, as in paper 000 §7.2). Procedural paths: a street walk
//! through the city's grid (straight on, left or right at each crossing), a
//! meandering path through the forest, a straight flight over the terrain;
//! or keyframes visited in order at a constant speed.
//!
//! Defined extremes: a speed of 0, a single keyframe, or keyframes all at
//! one point give a camera standing still (a zero-length path); after the
//! last keyframe the camera stays there.

use rand::Rng;

use crate::engine::RngStreams;
use crate::systems::error::{SystemError, invalid};

use super::config::CameraConfig;
use super::scene::{Layout, Scene};

/// A camera pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Eye position.
    pub eye: [f64; 3],
    /// Heading, radians (0 = +x, counter-clockwise).
    pub yaw: f64,
    /// Pitch, radians (positive looks up).
    pub pitch: f64,
}

/// Eye height above the ground on foot, metres.
pub const EYE_HEIGHT: f64 = 1.7;

/// The path names.
pub const PATHS: [&str; 5] = ["preset", "street", "forest", "flight", "keyframes"];

/// The path kind a config resolves to, and its speed.
fn resolve(cfg: &CameraConfig, scene: &Scene) -> Result<(&'static str, f64), SystemError> {
    let kind = match (cfg.path.as_str(), scene.layout) {
        ("preset", Layout::City { .. }) | ("street", _) => "street",
        ("preset", Layout::Forest { .. }) | ("forest", _) => "forest",
        ("preset", Layout::Terrain { .. }) | ("flight", _) => "flight",
        ("preset", Layout::Listed) | ("keyframes", _) => "keyframes",
        (other, _) => {
            return Err(invalid(
                "camera.path",
                format!("unknown path {other:?} (known: {})", PATHS.join(", ")),
            ));
        }
    };
    if kind == "street" && !matches!(scene.layout, Layout::City { .. }) {
        return Err(invalid(
            "camera.path",
            "a \"street\" walk needs the city preset's streets",
        ));
    }
    if kind == "forest" && !matches!(scene.layout, Layout::Forest { .. }) {
        return Err(invalid("camera.path", "a \"forest\" path needs the forest preset"));
    }
    if kind == "flight" && !matches!(scene.layout, Layout::Terrain { .. }) {
        return Err(invalid("camera.path", "a \"flight\" needs the terrain preset"));
    }
    if kind == "keyframes" && cfg.keyframes.is_empty() {
        return Err(invalid(
            "camera.keyframes",
            "a keyframes path (the path of a scene without a preset) needs at least one keyframe",
        ));
    }
    let default_speed = match kind {
        "street" => 10.0,
        "forest" => 3.0,
        "flight" => 60.0,
        _ => 5.0,
    };
    let speed = cfg.speed.unwrap_or(default_speed);
    if !(speed.is_finite() && (0.0..=1e5).contains(&speed)) {
        return Err(invalid(
            "camera.speed",
            format!("must be between 0 and 1e5 metres per second, got {speed}"),
        ));
    }
    Ok((kind, speed))
}

/// The path kind `cfg` resolves to in `scene` (`street`, `forest`,
/// `flight` or `keyframes`).
pub fn resolved_kind(cfg: &CameraConfig, scene: &Scene) -> Result<&'static str, SystemError> {
    resolve(cfg, scene).map(|(k, _)| k)
}

/// Checks the camera keys (view and path) against the scene.
pub fn validate(cfg: &CameraConfig, scene: &Scene) -> Result<(), SystemError> {
    if !(cfg.fov.is_finite() && cfg.fov >= 1.0 && cfg.fov <= 170.0) {
        return Err(invalid(
            "camera.fov",
            format!("must be between 1 and 170 degrees, got {}", cfg.fov),
        ));
    }
    for (key, v) in [("camera.width", cfg.width), ("camera.height", cfg.height)] {
        if !(1..=16384).contains(&v) {
            return Err(invalid(key, format!("must be between 1 and 16384 pixels, got {v}")));
        }
    }
    if !(cfg.near.is_finite() && cfg.near > 0.0) {
        return Err(invalid("camera.near", format!("must be > 0 metres, got {}", cfg.near)));
    }
    if !(cfg.far.is_finite() && cfg.far > cfg.near) {
        return Err(invalid(
            "camera.far",
            format!("must be a distance beyond camera.near ({}), got {}", cfg.near, cfg.far),
        ));
    }
    if !(cfg.look_around.is_finite() && (0.0..=180.0).contains(&cfg.look_around)) {
        return Err(invalid(
            "camera.look_around",
            format!("must be between 0 and 180 degrees, got {}", cfg.look_around),
        ));
    }
    if cfg.look_period.0 == 0 {
        return Err(invalid("camera.look_period", "must be longer than 0"));
    }
    for (i, k) in cfg.keyframes.iter().enumerate() {
        if k.position.iter().chain([&k.yaw, &k.pitch]).any(|v| !v.is_finite()) {
            return Err(invalid(
                &format!("camera.keyframes.{i}"),
                "position, yaw and pitch must be finite numbers",
            ));
        }
        if k.pitch.abs() > 89.0 {
            return Err(invalid(
                &format!("camera.keyframes.{i}.pitch"),
                format!("must be between -89 and 89 degrees, got {}", k.pitch),
            ));
        }
    }
    resolve(cfg, scene).map(|_| ())
}

/// The poses of `frames` frames `dt` seconds apart.
pub fn path(cfg: &CameraConfig, scene: &Scene, frames: u64, dt: f64, seed: u64) -> Result<Vec<Pose>, SystemError> {
    let (kind, speed) = resolve(cfg, scene)?;
    let step = speed * dt;
    let mut rng = RngStreams::new(seed).stream("camera.path");
    Ok(match (kind, scene.layout) {
        ("street", Layout::City { blocks, block, street }) => {
            let mut poses = street_walk(frames, step, blocks, block + street, street, &mut rng);
            look_around(&mut poses, cfg, dt);
            poses
        }
        ("forest", Layout::Forest { side }) => forest_walk(frames, step, side, &mut rng),
        ("flight", Layout::Terrain { side }) => (0..frames)
            .map(|f| {
                let s = f as f64 * step / std::f64::consts::SQRT_2;
                Pose {
                    eye: [0.1 * side + s, 0.1 * side + s, 200.0],
                    yaw: std::f64::consts::FRAC_PI_4,
                    pitch: (-15.0f64).to_radians(),
                }
            })
            .collect(),
        _ => keyframe_path(cfg, frames, step),
    })
}

/// A street walker's head turns, on poses `dt` seconds apart that look along
/// the street: the heading swings `camera.look_around` degrees to either
/// side, sinusoidally, once every `camera.look_period` (25° and 5 s unless
/// given). Paper 000 §7.2 says only that a path was recorded; how far its
/// walker looked around is not given, and it decides how much a frame's
/// load changes along the walk (experiments/table6-look-around.toml).
fn look_around(poses: &mut [Pose], cfg: &CameraConfig, dt: f64) {
    let amplitude = cfg.look_around.to_radians();
    // Whole picoseconds over 1e12: exact for whole seconds.
    let period = cfg.look_period.0 as f64 / 1e12;
    for (f, p) in poses.iter_mut().enumerate() {
        let t = f as f64 * dt;
        p.yaw += amplitude * (std::f64::consts::TAU * t / period).sin();
    }
}

/// Walks the street grid: from the crossing nearest the centre, along a
/// street; at every crossing straight on (1/2), left or right (1/4 each),
/// never leaving the city; looking along the street ([`look_around`]
/// turns the head).
fn street_walk(
    frames: u64,
    step: f64,
    blocks: u32,
    pitch: f64,
    street: f64,
    rng: &mut crate::engine::StreamRng,
) -> Vec<Pose> {
    let n = blocks as i64;
    let (mut ix, mut iy) = (n / 2, n / 2);
    let dirs = [(1i64, 0i64), (0, 1), (-1, 0), (0, -1)];
    let mut d = rng.random_range(0..4usize);
    let inside = |x: i64, y: i64| (0..=n).contains(&x) && (0..=n).contains(&y);
    let choose = |ix: i64, iy: i64, d: usize, rng: &mut crate::engine::StreamRng| -> usize {
        for _ in 0..16 {
            let r: f64 = rng.random_range(0.0..1.0);
            let nd = if r < 0.5 {
                d
            } else if r < 0.75 {
                (d + 1) % 4
            } else {
                (d + 3) % 4
            };
            if inside(ix + dirs[nd].0, iy + dirs[nd].1) {
                return nd;
            }
        }
        (d + 2) % 4
    };
    if !inside(ix + dirs[d].0, iy + dirs[d].1) {
        d = choose(ix, iy, d, rng);
    }
    let mut s = 0.0;
    let mut out = Vec::with_capacity(frames as usize);
    for _ in 0..frames {
        let (dx, dy) = dirs[d];
        let heading = (dy as f64).atan2(dx as f64);
        out.push(Pose {
            eye: [
                ix as f64 * pitch + 0.5 * street + dx as f64 * s,
                iy as f64 * pitch + 0.5 * street + dy as f64 * s,
                EYE_HEIGHT,
            ],
            yaw: heading,
            pitch: 3f64.to_radians(),
        });
        s += step;
        while s >= pitch && pitch > 0.0 {
            s -= pitch;
            ix += dirs[d].0;
            iy += dirs[d].1;
            d = choose(ix, iy, d, rng);
        }
    }
    out
}

/// A meandering path: the heading turns at a random rate that changes
/// smoothly; near the edge the walker turns back towards the centre.
fn forest_walk(frames: u64, step: f64, side: f64, rng: &mut crate::engine::StreamRng) -> Vec<Pose> {
    let c = 0.5 * side;
    let (mut x, mut y) = (c, c);
    let mut heading: f64 = rng.random_range(0.0..std::f64::consts::TAU);
    let mut rate = 0.0f64;
    let mut out = Vec::with_capacity(frames as usize);
    for _ in 0..frames {
        out.push(Pose {
            eye: [x, y, EYE_HEIGHT],
            yaw: heading,
            pitch: 0.0,
        });
        rate = 0.98 * rate + rng.random_range(-0.002..0.002);
        if ((x - c).powi(2) + (y - c).powi(2)).sqrt() > 0.4 * side {
            let to_centre = (c - y).atan2(c - x);
            let diff =
                (to_centre - heading + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
            rate = 0.02 * diff.signum();
        }
        heading += rate;
        x += step * heading.cos();
        y += step * heading.sin();
    }
    out
}

/// Keyframes visited in order at `step` metres per frame; yaw and pitch
/// interpolated along each segment; a segment of zero length is passed at
/// once; after the last keyframe the camera stays.
fn keyframe_path(cfg: &CameraConfig, frames: u64, step: f64) -> Vec<Pose> {
    let k = &cfg.keyframes;
    let pose = |i: usize| Pose {
        eye: k[i].position,
        yaw: k[i].yaw.to_radians(),
        pitch: k[i].pitch.to_radians(),
    };
    let mut lengths = Vec::with_capacity(k.len());
    for w in k.windows(2) {
        let d: f64 = (0..3)
            .map(|a| (w[1].position[a] - w[0].position[a]).powi(2))
            .sum::<f64>()
            .sqrt();
        lengths.push(d);
    }
    let total: f64 = lengths.iter().sum();
    (0..frames)
        .map(|f| {
            let mut s = (f as f64 * step).min(total);
            if total <= 0.0 || step <= 0.0 {
                return pose(if step > 0.0 { k.len() - 1 } else { 0 });
            }
            for (i, len) in lengths.iter().enumerate() {
                if s <= *len && *len > 0.0 {
                    let t = s / len;
                    let (a, b) = (pose(i), pose(i + 1));
                    let lerp = |p: f64, q: f64| p + t * (q - p);
                    return Pose {
                        eye: [
                            lerp(a.eye[0], b.eye[0]),
                            lerp(a.eye[1], b.eye[1]),
                            lerp(a.eye[2], b.eye[2]),
                        ],
                        yaw: lerp(a.yaw, b.yaw),
                        pitch: lerp(a.pitch, b.pitch),
                    };
                }
                s -= len;
            }
            pose(k.len() - 1)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::Duration;
    use crate::systems::walkthrough::config::SceneConfig;
    use crate::systems::walkthrough::scene::build_scene;
    use proptest::prelude::*;

    /// The smallest angle (radians) between `yaw` and a street's direction
    /// (a multiple of 90 degrees).
    fn off_street(yaw: f64) -> f64 {
        let q = std::f64::consts::FRAC_PI_2;
        let r = yaw.rem_euclid(q);
        r.min(q - r)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        /// A street walk's heading never leaves the street's direction by
        /// more than the look-around (below 45 degrees, where the nearest
        /// street direction is the walked one), and reaches it within a
        /// frame's step of the swing when the walk lasts a whole period.
        #[test]
        fn the_heading_stays_within_the_look_around(
            amplitude in 0.0f64..44.0,
            period_ms in 100u64..3000,
            seed in 0u64..1000,
        ) {
            let scene = build_scene(
                &SceneConfig { preset: Some("city".into()), scale: 0.01, ..SceneConfig::default() },
                seed,
            )
            .unwrap();
            let cfg = CameraConfig {
                look_around: amplitude,
                look_period: Duration(period_ms * 1_000_000_000),
                ..CameraConfig::default()
            };
            let dt = 1.0 / 60.0;
            let frames = (period_ms as f64 / 1e3 / dt).ceil() as u64 + 1;
            let poses = path(&cfg, &scene, frames, dt, seed).unwrap();
            let a = amplitude.to_radians();
            let widest = poses.iter().map(|p| off_street(p.yaw)).fold(0.0f64, f64::max);
            prop_assert!(widest <= a + 1e-9, "{widest} against {a}");
            // One frame moves the swing by at most 2 pi dt / period of its
            // amplitude: the widest frame is that close to the amplitude.
            let step = a * std::f64::consts::TAU * dt / (period_ms as f64 / 1e3);
            prop_assert!(widest >= a - step - 1e-9, "{widest} against {a} (step {step})");
        }
    }
}
