//! The picture: spheres as filled discs (points when smaller than a pixel)
//! over a depth buffer that keeps the nearest at each pixel, and the cube's
//! wireframe tested against that depth so edges hide behind near spheres.
use super::projection::Projection;
use super::theme::{Palette, Ramp};
use crate::engine::SphereView;
use crate::tui::look::{Camera, DrawStyle, LIGHT_STEPS};
use ratatui::buffer::{Buffer, Cell};
use ratatui::layout::Rect;
use ratatui::style::Color;

/// Pixels per cell the style draws with.
fn sub_of(style: DrawStyle) -> (usize, usize) {
    match style {
        DrawStyle::Shaded => (1, 2),
        _ => (2, 4),
    }
}

/// The colour ramp the style colours points with.
fn ramp_of(style: DrawStyle) -> Ramp {
    match style {
        DrawStyle::PointsDepth => Ramp::Depth,
        _ => Ramp::Speed,
    }
}

/// Everything the canvas depends on besides the spheres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scene {
    pub box_size: f64,
    pub camera: Camera,
    pub style: DrawStyle,
    /// `0..LIGHT_STEPS`.
    pub light: u8,
    pub palette: Palette,
    /// Cell height / width.
    pub aspect: f64,
}

const EMPTY: u8 = 0;
const EDGE: u8 = 255;
/// Sphere shades are 1..=SHADES.
const SHADES: u8 = 16;
const RAMP_LEVELS: u8 = 32;
const MONO_RAMP: &[u8] = b".:-=+*#%@";

/// Reused buffers, so a frame allocates nothing.
#[derive(Default)]
pub struct Raster {
    w: usize,
    h: usize,
    depth: Vec<f32>,
    shade: Vec<u8>,
    level: Vec<u8>,
}

impl Raster {
    pub fn new() -> Raster {
        Raster::default()
    }

    /// Rasterise `spheres` and write the cells of `area` in `buf`.
    pub fn draw(&mut self, spheres: &[SphereView], scene: &Scene, area: Rect, buf: &mut Buffer) {
        if area.width == 0 || area.height == 0 {
            return;
        }
        let (sx, sy) = sub_of(scene.style);
        let proj = Projection::new(
            area.width,
            area.height,
            sx,
            sy,
            scene.aspect,
            scene.camera,
            scene.box_size,
        );
        self.reset(proj.width, proj.height);
        self.spheres(spheres, scene, &proj);
        self.edges(scene, &proj);
        match scene.style {
            DrawStyle::Shaded => self.blocks(scene, area, buf),
            _ => self.braille(scene, area, buf),
        }
    }

    fn reset(&mut self, w: usize, h: usize) {
        self.w = w;
        self.h = h;
        let n = w * h;
        self.depth.clear();
        self.depth.resize(n, f32::INFINITY);
        self.shade.clear();
        self.shade.resize(n, EMPTY);
        self.level.clear();
        self.level.resize(n, 0);
    }

    fn spheres(&mut self, spheres: &[SphereView], scene: &Scene, proj: &Projection) {
        let (near, far) = proj.depth_range();
        let mean_sq = spheres
            .iter()
            .map(|s| f64::from(s.speed).powi(2))
            .sum::<f64>()
            / spheres.len().max(1) as f64;
        // Twice the rms speed is "hot": a Maxwell gas spreads over the ramp.
        let hot = 2.0 * mean_sq.sqrt();
        let (pw, ph) = proj.pixel_size();
        let light = light_dir(scene.light);
        let ring = scene.style != DrawStyle::Shaded;
        // In the spheres' own order: the depth test keeps the nearest at
        // each pixel, ties going to the later sphere, which is what drawing
        // them back to front gave, without sorting 100 000 of them.
        for s in spheres {
            let Some(p) = proj.project(s.pos.map(f64::from)) else {
                continue;
            };
            let t = match ramp_of(scene.style) {
                Ramp::Speed if hot > 0.0 => f64::from(s.speed) / hot,
                Ramp::Speed => 0.0,
                Ramp::Depth => 1.0 - (p.depth - near) / (far - near),
            };
            let level = (t.clamp(0.0, 1.0) * f64::from(RAMP_LEVELS - 1) + 0.5) as u8;
            let r = f64::from(s.radius) * p.unit; // cell widths
            self.disc(p.x, p.y, r / pw, r / ph, p.depth as f32, level, light, ring);
        }
    }

    /// A disc with radii `rx`, `ry` in pixels (the same length on screen).
    #[allow(clippy::too_many_arguments)] // a disc is its centre, two radii, depth, level, light and ring: plain values, named at the one call
    fn disc(
        &mut self,
        cx: f64,
        cy: f64,
        rx: f64,
        ry: f64,
        depth: f32,
        level: u8,
        light: [f64; 3],
        ring: bool,
    ) {
        let (w, h) = (self.w as isize, self.h as isize);
        if rx < 0.75 || ry < 0.75 {
            // Smaller than a pixel: one point.
            let (x, y) = (floor(cx), floor(cy));
            if x >= 0 && y >= 0 && x < w && y < h {
                let k = y as usize * self.w + x as usize;
                if depth <= self.depth[k] {
                    self.depth[k] = depth;
                    self.shade[k] = SHADES;
                    self.level[k] = level;
                }
            }
            return;
        }
        // A one-pixel gap around a disc keeps touching spheres apart when
        // every pixel has a single colour (braille).
        let gap = if ring { 1.0 } else { 0.0 };
        let (ox, oy) = (rx + gap, ry + gap);
        let y0 = floor(cy - oy).max(0);
        let y1 = ceil(cy + oy).min(h - 1);
        let (irx, iry, ioy) = (1.0 / rx, 1.0 / ry, 1.0 / oy);
        // Pixel x (centre x + 0.5) is within half-width `hw` of the centre
        // for x in this range, clipped to the raster.
        let span = |hw: f64| {
            let lo = ceil(cx - hw - 0.5).max(0);
            let hi = floor(cx + hw - 0.5).min(w - 1);
            (lo, hi)
        };
        for y in y0..=y1 {
            let fy = y as f64 + 0.5 - cy;
            let ey = fy * ioy;
            if ey * ey > 1.0 {
                continue;
            }
            let dy = fy * iry;
            let row = y as usize * self.w;
            let (i0, i1) = if dy * dy <= 1.0 {
                span(rx * (1.0 - dy * dy).sqrt())
            } else {
                (isize::MAX, isize::MIN)
            };
            if ring {
                // Clear the gap on both sides of the disc, then fill it.
                let (o0, o1) = span(ox * (1.0 - ey * ey).sqrt());
                for x in (o0..=o1).filter(|x| *x < i0 || *x > i1) {
                    self.put(row + x as usize, depth, EMPTY, None);
                }
                for x in i0..=i1 {
                    self.put(row + x as usize, depth, SHADES, Some(level));
                }
            } else {
                for x in i0..=i1 {
                    let dx = (x as f64 + 0.5 - cx) * irx;
                    let nz = (1.0 - dx * dx - dy * dy).max(0.0).sqrt();
                    let lit = (dx * light[0] + dy * light[1] + nz * light[2]).max(0.0);
                    let shade = 1 + (lit * f64::from(SHADES - 1) + 0.5) as u8;
                    self.put(row + x as usize, depth, shade, Some(level));
                }
            }
        }
    }

    /// Pixel `k` of a sphere `depth` away, unless something nearer holds
    /// it: its shade, and its colour level where it has one.
    #[inline]
    fn put(&mut self, k: usize, depth: f32, shade: u8, level: Option<u8>) {
        if depth <= self.depth[k] {
            self.depth[k] = depth;
            self.shade[k] = shade;
            if let Some(level) = level {
                self.level[k] = level;
            }
        }
    }

    fn edges(&mut self, scene: &Scene, proj: &Projection) {
        for (a, b) in Projection::cube_edges(scene.box_size) {
            let (Some(pa), Some(pb)) = (proj.project(a), proj.project(b)) else {
                continue;
            };
            let len = (pb.x - pa.x).abs().max((pb.y - pa.y).abs());
            let n = (len * 2.0).ceil().max(1.0) as usize;
            for i in 0..=n {
                let f = i as f64 / n as f64;
                let x = pa.x + (pb.x - pa.x) * f;
                let y = pa.y + (pb.y - pa.y) * f;
                // Perspective-correct depth along the edge is close enough
                // linear at this size; a small bias keeps edges over spheres
                // that touch the wall.
                let d = (pa.depth + (pb.depth - pa.depth) * f) as f32 - 1e-3;
                let (xi, yi) = (floor(x), floor(y));
                if xi < 0 || yi < 0 || xi >= self.w as isize || yi >= self.h as isize {
                    continue;
                }
                let k = yi as usize * self.w + xi as usize;
                if d < self.depth[k] {
                    self.depth[k] = d;
                    self.shade[k] = EDGE;
                }
            }
        }
    }

    fn colour(&self, scene: &Scene, k: usize) -> Color {
        match self.shade[k] {
            EDGE => scene.palette.edge(),
            s => scene.palette.ramp(
                ramp_of(scene.style),
                f32::from(self.level[k]) / f32::from(RAMP_LEVELS - 1),
                f32::from(s) / f32::from(SHADES),
            ),
        }
    }

    fn braille(&self, scene: &Scene, area: Rect, buf: &mut Buffer) {
        for cy in 0..usize::from(area.height) {
            for cx in 0..usize::from(area.width) {
                let (bits, nearest) = self.braille_dots(cx, cy);
                if bits == 0 {
                    continue;
                }
                let cell = &mut buf[(area.x + cx as u16, area.y + cy as u16)];
                cell.set_char(char::from_u32(0x2800 + bits).unwrap_or(' '));
                cell.set_fg(self.colour(scene, nearest));
            }
        }
    }

    /// The dots of the braille cell at (`cx`, `cy`) (2×4 pixels) as the
    /// pattern's bits, and the pixel nearest the eye among them (it gives
    /// the cell its colour).
    fn braille_dots(&self, cx: usize, cy: usize) -> (u32, usize) {
        const BITS: [[u32; 2]; 4] = [[0x01, 0x08], [0x02, 0x10], [0x04, 0x20], [0x40, 0x80]];
        let mut bits = 0u32;
        let mut nearest = (f32::INFINITY, usize::MAX);
        for (dy, row) in BITS.iter().enumerate() {
            for (dx, bit) in row.iter().enumerate() {
                let k = (cy * 4 + dy) * self.w + cx * 2 + dx;
                if self.shade[k] == EMPTY {
                    continue;
                }
                bits |= bit;
                if self.depth[k] < nearest.0 {
                    nearest = (self.depth[k], k);
                }
            }
        }
        (bits, nearest.1)
    }

    fn blocks(&self, scene: &Scene, area: Rect, buf: &mut Buffer) {
        let mono = !scene.palette.has_color();
        for cy in 0..usize::from(area.height) {
            for cx in 0..usize::from(area.width) {
                let top = (cy * 2) * self.w + cx;
                let bot = top + self.w;
                let (st, sb) = (self.shade[top], self.shade[bot]);
                if st == EMPTY && sb == EMPTY {
                    continue;
                }
                let cell = &mut buf[(area.x + cx as u16, area.y + cy as u16)];
                if mono {
                    cell.set_char(mono_glyph(st, sb));
                    continue;
                }
                match (st != EMPTY, sb != EMPTY) {
                    (true, false) => {
                        cell.set_char('▀').set_fg(self.colour(scene, top));
                    }
                    (false, true) => {
                        cell.set_char('▄').set_fg(self.colour(scene, bot));
                    }
                    _ => both_halves(cell, self.colour(scene, top), self.colour(scene, bot)),
                }
            }
        }
    }
}

/// Without colour, a half-block cell's brightness as a glyph ramp: the
/// brighter of its two pixels' shades (`st`, `sb`), or `+` on an edge.
fn mono_glyph(st: u8, sb: u8) -> char {
    if st == EDGE || sb == EDGE {
        return '+';
    }
    let s = usize::from(st.max(sb));
    let i = (s * MONO_RAMP.len()).div_ceil(usize::from(SHADES)) - 1;
    char::from(MONO_RAMP[i.min(MONO_RAMP.len() - 1)])
}

// `f64::floor` and `ceil` are library calls on baseline x86-64; these are
// a cast and a compare, and they are most of the cost of a small disc.
fn floor(v: f64) -> isize {
    let i = v as isize;
    if (i as f64) > v { i - 1 } else { i }
}

fn ceil(v: f64) -> isize {
    let i = v as isize;
    if (i as f64) < v { i + 1 } else { i }
}

/// Unit light direction in screen space (x right, y down, z to the viewer),
/// from the upper left at step 0, going round.
fn light_dir(step: u8) -> [f64; 3] {
    let az = std::f64::consts::TAU * f64::from(step % LIGHT_STEPS) / f64::from(LIGHT_STEPS)
        + 1.25 * std::f64::consts::PI;
    let (s, c) = az.sin_cos();
    let (x, y, z) = (0.7 * c, 0.7 * s, 0.714);
    let n = (x * x + y * y + z * z).sqrt();
    [x / n, y / n, z / n]
}

/// A cell whose two halves both hold a sphere: one full block when they
/// share a colour.
fn both_halves(cell: &mut Cell, top: Color, bottom: Color) {
    if top == bottom {
        cell.set_char('█').set_fg(top);
    } else {
        cell.set_char('▀').set_fg(top).set_bg(bottom);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(style: DrawStyle) -> Scene {
        Scene {
            box_size: 1.0,
            camera: Camera {
                yaw: 0.0,
                pitch: 0.0,
            },
            style,
            light: 0,
            palette: Palette::C16,
            aspect: 2.0,
        }
    }

    /// The lit pixels (neither empty nor an edge), as (x, y, shade).
    fn lit(r: &Raster) -> impl Iterator<Item = (usize, usize, u8)> + '_ {
        let all = (0..r.h).flat_map(move |y| (0..r.w).map(move |x| (x, y, r.shade[y * r.w + x])));
        all.filter(|&(_, _, v)| v != EMPTY && v != EDGE)
    }

    fn sphere(pos: [f64; 3], radius: f64, speed: f64) -> SphereView {
        SphereView {
            pos: pos.map(|x| x as f32),
            radius: radius as f32,
            speed: speed as f32,
        }
    }

    #[test]
    fn a_disc_is_round_in_pixels_whatever_the_cell_aspect() {
        for aspect in [1.6, 2.0, 2.5] {
            let mut r = Raster::new();
            let mut sc = scene(DrawStyle::PointsSpeed);
            sc.aspect = aspect;
            let area = Rect::new(0, 0, 60, 30);
            let mut buf = Buffer::empty(area);
            r.draw(&[sphere([0.5, 0.5, 0.5], 0.2, 1.0)], &sc, area, &mut buf);
            // Width and height of the lit region, in cell widths.
            let (xs, ys): (Vec<usize>, Vec<usize>) = lit(&r).map(|(x, y, _)| (x, y)).unzip();
            let wide = (xs.iter().max().unwrap() - xs.iter().min().unwrap() + 1) as f64 * 0.5;
            let tall =
                (ys.iter().max().unwrap() - ys.iter().min().unwrap() + 1) as f64 * aspect / 4.0;
            assert!(
                (wide / tall - 1.0).abs() < 0.15,
                "aspect {aspect}: {wide} x {tall}"
            );
        }
    }

    #[test]
    fn the_nearer_sphere_wins_the_cell() {
        let mut r = Raster::new();
        let sc = scene(DrawStyle::PointsSpeed);
        let area = Rect::new(0, 0, 40, 20);
        let mut buf = Buffer::empty(area);
        // Same screen spot, the slow one nearer (y small is near at yaw 0).
        let spheres = [
            sphere([0.5, 0.8, 0.5], 0.1, 2.0),
            sphere([0.5, 0.2, 0.5], 0.1, 0.0),
        ];
        r.draw(&spheres, &sc, area, &mut buf);
        let centre = &buf[(20, 10)];
        assert_eq!(centre.symbol(), "⣿");
        assert_eq!(centre.fg, Color::LightBlue);
        // Drawn in the other order, the answer is the same.
        let mut buf2 = Buffer::empty(area);
        r.draw(&[spheres[1], spheres[0]], &sc, area, &mut buf2);
        assert_eq!(buf, buf2);
    }

    #[test]
    fn tiny_spheres_are_single_points() {
        let mut r = Raster::new();
        let sc = scene(DrawStyle::PointsSpeed);
        let area = Rect::new(0, 0, 40, 20);
        let mut buf = Buffer::empty(area);
        r.draw(&[sphere([0.5, 0.5, 0.5], 1e-4, 1.0)], &sc, area, &mut buf);
        let lit = memchr::memchr_iter(SHADES, &r.shade).count();
        assert_eq!(lit, 1);
    }

    #[test]
    fn the_light_brightens_the_side_it_comes_from() {
        let mut r = Raster::new();
        let mut sc = scene(DrawStyle::Shaded);
        sc.palette = Palette::True;
        let area = Rect::new(0, 0, 60, 30);
        let mut buf = Buffer::empty(area);
        let s = [sphere([0.5, 0.5, 0.5], 0.25, 0.0)];
        let mean_x = |r: &Raster| {
            let (mut sum, mut wsum) = (0.0, 0.0);
            for (x, _, v) in lit(r) {
                sum += x as f64 * f64::from(v);
                wsum += f64::from(v);
            }
            sum / wsum
        };
        r.draw(&s, &sc, area, &mut buf);
        let left = mean_x(&r);
        sc.light = LIGHT_STEPS / 2;
        r.draw(&s, &sc, area, &mut buf);
        let right = mean_x(&r);
        assert!(
            left + 1.0 < right,
            "light 0 is upper left: {left} vs {right}"
        );
    }
}
