//! Per frame: view-frustum culling of bounding spheres, the view cell's
//! potentially visible set (PVS), and each visible object's screen
//! projection (paper 000 §5.2, Figure 5: the angle α between the
//! supporting lines of the bounding sphere, clipped to the frustum, and the
//! viewing direction γ, φ in the object's frame).
//!
//! Pixels, two readings:
//! - `disk_pixels`: the bounding sphere's projected disk clipped to the
//!   viewport, what an estimator can compute cheaply (the heuristics'
//!   #pix);
//! - `covered_pixels`, the simulator's truth: the box's share of its
//!   sphere's disk seen from that direction, κ(γ, φ) = (|v_x| d h +
//!   |v_y| w h + max(v_z, 0) w d) / (π R²) (the parallel projection of a
//!   box, bottom hidden by the ground), times the clipped disk, times the object's own
//!   overdraw. The ratio depends on the object and the direction: what
//!   per-object sampling captures and a single constant per pixel cannot.
//!
//! A camera inside a bounding sphere (distance < radius): α = π and the
//! disk is the whole viewport (the object covers κ of the screen): a
//! defined result, not an error.

use std::collections::HashMap;

use super::camera::Pose;
use super::config::CameraConfig;
use super::estimators::Features;
use super::scene::{Layout, Object, Prototype, Scene};

/// The camera's view: basis, focal length and frustum.
#[derive(Debug, Clone, Copy)]
pub struct View {
    /// Eye.
    pub eye: [f64; 3],
    right: [f64; 3],
    up: [f64; 3],
    fwd: [f64; 3],
    /// Focal length, pixels.
    pub focal: f64,
    /// Viewport width, pixels.
    pub width: f64,
    /// Viewport height, pixels.
    pub height: f64,
    near: f64,
    far: f64,
    planes: [[f64; 3]; 4],
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn norm3(a: [f64; 3]) -> [f64; 3] {
    let l = dot(a, a).sqrt();
    [a[0] / l, a[1] / l, a[2] / l]
}

impl View {
    /// The view of `pose` with the camera's field of view and viewport.
    pub fn new(pose: &Pose, cam: &CameraConfig) -> View {
        let (cy, sy) = (pose.yaw.cos(), pose.yaw.sin());
        let (cp, sp) = (pose.pitch.cos(), pose.pitch.sin());
        let fwd = [cp * cy, cp * sy, sp];
        let right = [sy, -cy, 0.0];
        let up = [-sp * cy, -sp * sy, cp];
        let (w, h) = (cam.width as f64, cam.height as f64);
        let tan_h = (0.5 * cam.fov.to_radians()).tan();
        let focal = 0.5 * w / tan_h;
        let tan_v = 0.5 * h / focal;
        // Outward normals of the side planes in view coordinates (x right, y up, z forward).
        let plane = |a: f64, b: f64, t: f64| norm3([a, b, -t]);
        View {
            eye: pose.eye,
            right,
            up,
            fwd,
            focal,
            width: w,
            height: h,
            near: cam.near,
            far: cam.far,
            planes: [
                plane(1.0, 0.0, tan_h),
                plane(-1.0, 0.0, tan_h),
                plane(0.0, 1.0, tan_v),
                plane(0.0, -1.0, tan_v),
            ],
        }
    }

    /// A point in view coordinates (x right, y up, z forward).
    pub fn to_view(&self, p: [f64; 3]) -> [f64; 3] {
        let d = sub(p, self.eye);
        [dot(d, self.right), dot(d, self.up), dot(d, self.fwd)]
    }

    /// Whether a sphere intersects the view frustum (conservative at the
    /// frustum's corners, as usual for plane tests).
    pub fn sees_sphere(&self, center: [f64; 3], radius: f64) -> bool {
        let p = self.to_view(center);
        if p[2] + radius < self.near || p[2] - radius > self.far {
            return false;
        }
        self.planes.iter().all(|n| dot(*n, p) <= radius)
    }

    /// Whether a point lies inside the frustum.
    pub fn contains_point(&self, q: [f64; 3]) -> bool {
        let p = self.to_view(q);
        p[2] >= self.near && p[2] <= self.far && self.planes.iter().all(|n| dot(*n, p) <= 0.0)
    }

    /// Area of the viewport, pixels.
    pub fn screen_pixels(&self) -> f64 {
        self.width * self.height
    }
}

/// Area of a disk of radius `r` centred at (`cx`, `cy`) inside the
/// rectangle [0, w] x [0, h]: exact when the disk lies inside or covers the
/// rectangle, else a 128-strip midpoint integral of the clipped chords.
pub fn disk_in_rect(cx: f64, cy: f64, r: f64, w: f64, h: f64) -> f64 {
    if r <= 0.0 {
        return 0.0;
    }
    if cx - r >= 0.0 && cx + r <= w && cy - r >= 0.0 && cy + r <= h {
        return std::f64::consts::PI * r * r;
    }
    let corners = [(0.0, 0.0), (w, 0.0), (0.0, h), (w, h)];
    if corners
        .iter()
        .all(|(x, y)| (x - cx).powi(2) + (y - cy).powi(2) <= r * r)
    {
        return w * h;
    }
    let (x0, x1) = ((cx - r).max(0.0), (cx + r).min(w));
    if x1 <= x0 {
        return 0.0;
    }
    const STRIPS: usize = 128;
    let dx = (x1 - x0) / STRIPS as f64;
    let mut area = 0.0;
    for i in 0..STRIPS {
        let x = x0 + (i as f64 + 0.5) * dx;
        let c = (r * r - (x - cx).powi(2)).max(0.0).sqrt();
        area += ((cy + c).min(h) - (cy - c).max(0.0)).max(0.0) * dx;
    }
    area
}

/// The box's share of its bounding sphere's disk seen from unit direction
/// `v` (object frame, from the centre towards the eye).
pub fn coverage(size: [f64; 3], v: [f64; 3]) -> f64 {
    let [w, d, h] = size;
    let r2 = 0.25 * (w * w + d * d + h * h);
    (v[0].abs() * d * h + v[1].abs() * w * h + v[2].max(0.0) * w * d) / (std::f64::consts::PI * r2)
}

/// The unit direction (γ, φ) in the object frame.
pub fn direction(gamma: f64, phi: f64) -> [f64; 3] {
    [phi.cos() * gamma.cos(), phi.cos() * gamma.sin(), phi.sin()]
}

/// What a visible object looks like this frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projection {
    /// The bounding sphere's disk clipped to the viewport, pixels.
    pub disk_pixels: f64,
    /// Pixels the object covers (the simulator's truth, overdraw included).
    pub covered_pixels: f64,
    /// α clipped to the frustum: the angle of a disk of the clipped area.
    pub alpha: f64,
    /// Azimuth of the eye in the object frame, [0, 2π).
    pub gamma: f64,
    /// Elevation of the eye in the object frame.
    pub phi: f64,
    /// The eye is inside the bounding sphere.
    pub inside: bool,
}

/// α of a disk of `pixels` area seen with focal length `focal`.
pub fn alpha_of_disk(pixels: f64, focal: f64) -> f64 {
    2.0 * ((pixels / std::f64::consts::PI).sqrt() / focal).atan()
}

/// Projects an object that passed culling.
pub fn project(view: &View, o: &Object, proto: &Prototype) -> Projection {
    let to_eye = sub(view.eye, o.center);
    let dist = dot(to_eye, to_eye).sqrt();
    let inside = dist <= o.radius;
    let disk = if inside {
        view.screen_pixels()
    } else {
        let p = view.to_view(o.center);
        let tan_half = o.radius / (dist * dist - o.radius * o.radius).sqrt();
        let r = view.focal * tan_half;
        let z = p[2].max(o.radius);
        let cx = 0.5 * view.width + view.focal * p[0] / z;
        let cy = 0.5 * view.height - view.focal * p[1] / z;
        disk_in_rect(cx, cy, r, view.width, view.height)
    };
    // The eye's direction in the object frame (rotated by -yaw).
    let v = if dist > 0.0 {
        [to_eye[0] / dist, to_eye[1] / dist, to_eye[2] / dist]
    } else {
        [0.0, 0.0, 1.0]
    };
    let (c, s) = (o.yaw.cos(), o.yaw.sin());
    let vo = [c * v[0] + s * v[1], -s * v[0] + c * v[1], v[2]];
    let gamma = vo[1].atan2(vo[0]).rem_euclid(std::f64::consts::TAU);
    let phi = vo[2].clamp(-1.0, 1.0).asin();
    Projection {
        disk_pixels: disk,
        covered_pixels: coverage(proto.size, vo) * proto.overdraw * disk,
        alpha: alpha_of_disk(disk, view.focal),
        gamma,
        phi,
        inside,
    }
}

/// The same projection for an object viewed at clipped angle `alpha` from
/// direction (`gamma`, `phi`), its disk centred (the preprocess's sample
/// views: the eye at distance R / sin(α/2) on that direction, looking at
/// the centre; a disk larger than the viewport is clipped).
pub fn sample_projection(
    proto: &Prototype,
    alpha: f64,
    gamma: f64,
    phi: f64,
    focal: f64,
    w: f64,
    h: f64,
) -> Projection {
    let r = focal * (0.5 * alpha).tan();
    let disk = disk_in_rect(0.5 * w, 0.5 * h, r, w, h);
    let vo = direction(gamma, phi);
    Projection {
        disk_pixels: disk,
        covered_pixels: coverage(proto.size, vo) * proto.overdraw * disk,
        alpha: alpha_of_disk(disk, focal),
        gamma,
        phi,
        inside: false,
    }
}

/// The potentially visible sets of the view cells visited, computed when a
/// cell is first entered. In the city, a block is visible from a cell when
/// one of 25 sight lines (cell corners and centre to points inset 1 m from
/// the block's corners and its centre) reaches it without entering another
/// block (blocks are opaque from the ground: the 2.5D occlusion of a street
/// grid, tested at 2 m steps along each line); every object of a visible
/// block is in the set. Elsewhere a cell's set is every object within the
/// far plane of the cell.
#[derive(Debug, Default)]
pub struct Pvs {
    cells: HashMap<(i64, i64), Vec<u32>>,
}

impl Pvs {
    /// Cells computed so far.
    pub fn cells_visited(&self) -> usize {
        self.cells.len()
    }

    /// The set of the cell holding `eye` (objects by index, ascending).
    pub fn set(&mut self, scene: &Scene, cell: f64, eye: [f64; 3], far: f64) -> &[u32] {
        let key = ((eye[0] / cell).floor() as i64, (eye[1] / cell).floor() as i64);
        self.cells.entry(key).or_insert_with(|| compute(scene, cell, key, far))
    }

    /// Culling on the object level: calls `f` with each object (by index)
    /// that `view`, from `eye`, may draw: in the view cell's set when the
    /// scene has view cells (every object otherwise), in ascending order,
    /// whose bounding sphere meets the frustum.
    pub fn for_each_visible(&mut self, scene: &Scene, eye: [f64; 3], view: &View, far: f64, mut f: impl FnMut(u32)) {
        let mut one = |i: u32| {
            let o = &scene.objects[i as usize];
            if view.sees_sphere(o.center, o.radius) {
                f(i);
            }
        };
        match scene.view_cell {
            Some(c) => self.set(scene, c, eye, far).iter().for_each(|&i| one(i)),
            None => (0..scene.objects.len() as u32).for_each(one),
        }
    }
}

fn compute(scene: &Scene, cell: f64, key: (i64, i64), far: f64) -> Vec<u32> {
    let (x0, y0) = (key.0 as f64 * cell, key.1 as f64 * cell);
    let from = [
        (x0, y0),
        (x0 + cell, y0),
        (x0, y0 + cell),
        (x0 + cell, y0 + cell),
        (x0 + 0.5 * cell, y0 + 0.5 * cell),
    ];
    let mid = (x0 + 0.5 * cell, y0 + 0.5 * cell);
    let reach = far + 0.5 * cell * std::f64::consts::SQRT_2;
    let Layout::City { blocks, block, street } = scene.layout else {
        return (0..scene.objects.len() as u32)
            .filter(|&i| {
                let o = &scene.objects[i as usize];
                ((o.center[0] - mid.0).powi(2) + (o.center[1] - mid.1).powi(2)).sqrt() - o.radius <= reach
            })
            .collect();
    };
    let pitch = block + street;
    // Which block holds (x, y), if any.
    let block_at = |x: f64, y: f64| -> Option<u32> {
        let (i, j) = ((x / pitch).floor(), (y / pitch).floor());
        if i < 0.0 || j < 0.0 || i >= blocks as f64 || j >= blocks as f64 {
            return None;
        }
        let (u, v) = (x - i * pitch, y - j * pitch);
        (u > street && v > street).then_some(j as u32 * blocks + i as u32)
    };
    let start_blocks: Vec<Option<u32>> = from.iter().map(|&(x, y)| block_at(x + 1e-6, y + 1e-6)).collect();
    let mut visible = vec![false; (blocks * blocks) as usize];
    for b in 0..blocks * blocks {
        let (i, j) = ((b % blocks) as f64, (b / blocks) as f64);
        let (bx, by) = (i * pitch + street, j * pitch + street);
        let to = [
            (bx + 1.0, by + 1.0),
            (bx + block - 1.0, by + 1.0),
            (bx + 1.0, by + block - 1.0),
            (bx + block - 1.0, by + block - 1.0),
            (bx + 0.5 * block, by + 0.5 * block),
        ];
        let near_edge = ((mid.0 - (bx + 0.5 * block)).abs() - 0.5 * block)
            .max(0.0)
            .hypot(((mid.1 - (by + 0.5 * block)).abs() - 0.5 * block).max(0.0));
        if near_edge > reach {
            continue;
        }
        'lines: for (fi, &(fx, fy)) in from.iter().enumerate() {
            for &(tx, ty) in &to {
                let len = (tx - fx).hypot(ty - fy);
                let steps = (len / 2.0).ceil().max(1.0) as u32;
                let mut clear = true;
                for s in 1..steps {
                    let t = s as f64 / steps as f64;
                    match block_at(fx + t * (tx - fx), fy + t * (ty - fy)) {
                        Some(h) if h == b => break,
                        Some(h) if Some(h) == start_blocks[fi] => {}
                        Some(_) => {
                            clear = false;
                            break;
                        }
                        None => {}
                    }
                }
                if clear {
                    visible[b as usize] = true;
                    break 'lines;
                }
            }
        }
    }
    (0..scene.objects.len() as u32)
        .filter(|&i| {
            let o = &scene.objects[i as usize];
            o.block == u32::MAX || visible.get(o.block as usize).copied().unwrap_or(true)
        })
        .collect()
}

/// One object's features at `level` in projection `p`.
pub(super) fn features(scene: &Scene, proto: u32, level: usize, p: &Projection) -> Features {
    let l = scene.protos[proto as usize].levels[level];
    Features {
        triangles: l.triangles as f64,
        transformed: l.transformed as f64,
        vertices: l.vertices as f64,
        pixels: p.disk_pixels,
    }
}
