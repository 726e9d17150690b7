//! What the user chose to look at: the draw style (`v`), the camera
//! (arrows) and the light (`l`). The state owns them; the view draws by
//! them.
use strum::IntoStaticStr;

/// `v` cycles these.
#[derive(Clone, Copy, Debug, PartialEq, Eq, IntoStaticStr)]
pub enum DrawStyle {
    /// Braille dots (2×4 per cell), one colour per cell, coloured by speed.
    #[strum(serialize = "braille, speed")]
    PointsSpeed,
    /// Braille dots coloured by depth (near bright, far dark).
    #[strum(serialize = "braille, depth")]
    PointsDepth,
    /// Half-blocks (1×2 per cell), each pixel lit by the light.
    #[strum(serialize = "shaded blocks")]
    Shaded,
}

impl DrawStyle {
    /// The `v` key's cycle, in the order of declaration (a match, as every
    /// cycle of keys is written: the compiler sees a style left out).
    #[must_use]
    pub fn next(self) -> DrawStyle {
        match self {
            DrawStyle::PointsSpeed => DrawStyle::PointsDepth,
            DrawStyle::PointsDepth => DrawStyle::Shaded,
            DrawStyle::Shaded => DrawStyle::PointsSpeed,
        }
    }

    pub fn name(self) -> &'static str {
        self.into()
    }
}

/// Light positions `l` steps through: azimuths around the view axis.
pub const LIGHT_STEPS: u8 = 8;

/// The camera orbits the cube's centre; arrows change yaw and pitch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Radians around the vertical axis.
    pub yaw: f64,
    /// Radians above the horizon.
    pub pitch: f64,
}

impl Default for Camera {
    fn default() -> Self {
        Camera {
            yaw: 0.5,
            pitch: 0.35,
        }
    }
}
