//! Perspective camera: world points to sub-cell pixels. Lengths on screen are
//! measured in cell widths, so a pixel's width and height come from the cell
//! aspect and circles stay circles whatever the font.
use crate::tui::look::Camera;

/// Eye distance from the cube centre, in box lengths: near enough for a clear
/// perspective, far enough that the near corner doesn't balloon.
const EYE_DISTANCE: f64 = 2.6;

/// A pixel grid over a canvas of `cols`×`rows` cells, `sub_x`×`sub_y` pixels
/// per cell, for a cell `aspect` (height / width) times as tall as wide.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projection {
    pub width: usize,
    pub height: usize,
    /// Pixel size in cell widths.
    px_w: f64,
    px_h: f64,
    /// Focal length in cell widths.
    focal: f64,
    centre_x: f64,
    centre_y: f64,
    rot: [[f64; 3]; 3],
    eye: f64,
    half_box: f64,
    scale: f64,
}

/// A projected point: pixel coordinates (fractional), depth from the eye in
/// box lengths, and how many pixels one box length spans there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projected {
    pub x: f64,
    pub y: f64,
    pub depth: f64,
    /// Cell widths per world unit at this depth.
    pub unit: f64,
}

impl Projection {
    pub fn new(
        cols: u16,
        rows: u16,
        sub_x: usize,
        sub_y: usize,
        aspect: f64,
        camera: Camera,
        box_size: f64,
    ) -> Projection {
        let width = usize::from(cols) * sub_x;
        let height = usize::from(rows) * sub_y;
        let span_w = f64::from(cols);
        let span_h = f64::from(rows) * aspect;
        // The cube's bounding sphere (radius √3/2 in box lengths) fits the
        // shorter side with a small margin.
        let r = 3f64.sqrt() / 2.0;
        let fit = r / (EYE_DISTANCE * EYE_DISTANCE - r * r).sqrt();
        let focal = 0.96 * span_w.min(span_h) / 2.0 / fit;
        let (sy, cy) = camera.yaw.sin_cos();
        let (sp, cp) = camera.pitch.sin_cos();
        // Yaw about the vertical (world z) axis, then pitch; screen y grows down.
        let rot = [
            [cy, sy, 0.0],
            [-sy * sp, cy * sp, cp],
            [-sy * cp, cy * cp, -sp],
        ];
        Projection {
            width,
            height,
            px_w: 1.0 / sub_x as f64,
            px_h: aspect / sub_y as f64,
            focal,
            centre_x: span_w / 2.0,
            centre_y: span_h / 2.0,
            rot,
            eye: EYE_DISTANCE,
            half_box: box_size / 2.0,
            scale: 1.0 / box_size.max(f64::MIN_POSITIVE),
        }
    }

    /// Pixel width and height in cell widths.
    pub fn pixel_size(&self) -> (f64, f64) {
        (self.px_w, self.px_h)
    }

    /// World point to screen; `None` behind the eye.
    pub fn project(&self, p: [f64; 3]) -> Option<Projected> {
        let c = [
            (p[0] - self.half_box) * self.scale,
            (p[1] - self.half_box) * self.scale,
            (p[2] - self.half_box) * self.scale,
        ];
        let dot = |r: [f64; 3]| r[0] * c[0] + r[1] * c[1] + r[2] * c[2];
        let x = dot(self.rot[0]);
        // Screen y is down, world z is up.
        let y = -dot(self.rot[1]);
        let depth = self.eye + dot(self.rot[2]);
        if depth <= 1e-3 {
            return None;
        }
        let unit = self.focal / depth;
        Some(Projected {
            x: (self.centre_x + x * unit) / self.px_w,
            y: (self.centre_y + y * unit) / self.px_h,
            depth,
            unit: unit * self.scale,
        })
    }

    /// The nearest and farthest depth any point of the cube can have.
    pub fn depth_range(&self) -> (f64, f64) {
        let r = 3f64.sqrt() / 2.0;
        (self.eye - r, self.eye + r)
    }

    /// The cube's 12 edges as pairs of corners.
    pub fn cube_edges(box_size: f64) -> [([f64; 3], [f64; 3]); 12] {
        let l = box_size;
        let c = |i: u8| {
            [
                if i & 1 != 0 { l } else { 0.0 },
                if i & 2 != 0 { l } else { 0.0 },
                if i & 4 != 0 { l } else { 0.0 },
            ]
        };
        let mut out = [([0.0; 3], [0.0; 3]); 12];
        let mut k = 0;
        for i in 0u8..8 {
            for bit in [1u8, 2, 4] {
                if i & bit == 0 {
                    out[k] = (c(i), c(i | bit));
                    k += 1;
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_centre_lands_mid_canvas_and_circles_stay_round() {
        let p = Projection::new(80, 40, 2, 4, 2.0, Camera::default(), 1.0);
        let c = p.project([0.5, 0.5, 0.5]).unwrap();
        assert!(
            (c.x - 80.0).abs() < 1e-9 && (c.y - 80.0).abs() < 1e-9,
            "{c:?}"
        );
        // A radius in pixels: same number of cell widths across and down.
        let (pw, ph) = p.pixel_size();
        assert_eq!((pw, ph), (0.5, 0.5));
        let q = Projection::new(80, 40, 1, 2, 2.4, Camera::default(), 1.0);
        assert_eq!(q.pixel_size(), (1.0, 1.2));
    }

    #[test]
    fn the_whole_cube_fits_whatever_the_view() {
        for (yaw, pitch) in [(0.0, 0.0), (0.5, 0.35), (2.0, -1.2), (3.9, 1.4)] {
            let p = Projection::new(60, 20, 2, 4, 2.0, Camera { yaw, pitch }, 2.0);
            for (a, b) in Projection::cube_edges(2.0) {
                for q in [a, b] {
                    let s = p.project(q).unwrap();
                    assert!(s.x >= 0.0 && s.x < p.width as f64, "{s:?}");
                    assert!(s.y >= 0.0 && s.y < p.height as f64, "{s:?}");
                    let (near, far) = p.depth_range();
                    assert!(s.depth >= near - 1e-9 && s.depth <= far + 1e-9);
                }
            }
        }
    }

    #[test]
    fn nearer_things_look_bigger() {
        let p = Projection::new(
            80,
            40,
            2,
            4,
            2.0,
            Camera {
                yaw: 0.0,
                pitch: 0.0,
            },
            1.0,
        );
        let near = p.project([0.5, 0.0, 0.5]).unwrap();
        let far = p.project([0.5, 1.0, 0.5]).unwrap();
        assert!(near.depth < far.depth);
        assert!(near.unit > far.unit);
    }
}
