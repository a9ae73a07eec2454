//! The axes and units of exported files. Inside, the engine works in metres with +Z up (gravity
//! along −Z). Files follow what their readers expect: glTF is +Y up in metres by its
//! specification; OBJ has no rule, and Blender, Maya, Houdini and CLO read it +Y up, so OBJ is
//! +Y up by default with `up: "z"` for tools that want the engine's frame; every mesh export
//! may be scaled to centimetres or millimetres (CLO and Marvelous Designer work in mm).
//!
//! The +Y-up frame is the engine's turned −90° about X: `(x, y, z) ↦ (x, z, −y)` (a rotation,
//! so handedness and windings are kept; the engine's −Y, the front of a mannequin, becomes +Z,
//! glTF's front). Blender's importers turn it back, so what hangs down in the engine hangs
//! down along Blender's −Z. The conversion only swaps coordinates and flips a sign: a point
//! goes through and back exactly.

use super::Vec3;

/// Which axis of the file is up.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum UpAxis {
    /// +Y up (glTF, OBJ as Blender and Maya read it).
    #[default]
    Y,
    /// +Z up (the engine's own frame; Blender's, 3ds Max's and USD's when so declared).
    Z,
}

/// Length unit of the file's coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Units {
    /// Metres (SI, glTF's unit).
    #[default]
    Metres,
    /// Centimetres.
    Centimetres,
    /// Millimetres (CLO, Marvelous Designer, DXF-AAMA).
    Millimetres,
}

impl Units {
    /// File units per metre.
    pub fn per_metre(self) -> f64 {
        match self {
            Units::Metres => 1.0,
            Units::Centimetres => 100.0,
            Units::Millimetres => 1000.0,
        }
    }

    /// The unit's symbol: `m`, `cm` or `mm`.
    pub fn symbol(self) -> &'static str {
        match self {
            Units::Metres => "m",
            Units::Centimetres => "cm",
            Units::Millimetres => "mm",
        }
    }

    /// Parses `m`, `cm` or `mm`.
    pub fn parse(s: &str) -> Result<Units, String> {
        match s {
            "m" => Ok(Units::Metres),
            "cm" => Ok(Units::Centimetres),
            "mm" => Ok(Units::Millimetres),
            _ => Err(format!("units `{s}`: expected \"m\", \"cm\" or \"mm\"")),
        }
    }
}

impl UpAxis {
    /// Parses `y` or `z` (either case).
    pub fn parse(s: &str) -> Result<UpAxis, String> {
        match s {
            "y" | "Y" => Ok(UpAxis::Y),
            "z" | "Z" => Ok(UpAxis::Z),
            _ => Err(format!("up axis `{s}`: expected \"y\" or \"z\"")),
        }
    }
}

/// The frame of an exported file: its up axis and its unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ExportFrame {
    /// The file's up axis.
    pub up: UpAxis,
    /// The file's length unit.
    pub units: Units,
}

impl ExportFrame {
    /// glTF's frame in metres (+Y up), also the OBJ default.
    pub const Y_UP_METRES: ExportFrame = ExportFrame {
        up: UpAxis::Y,
        units: Units::Metres,
    };

    /// The engine's own frame (+Z up, metres).
    pub const ENGINE: ExportFrame = ExportFrame {
        up: UpAxis::Z,
        units: Units::Metres,
    };

    /// A point of the engine (metres, +Z up) in the file's frame and unit.
    #[inline]
    pub fn point(&self, p: &Vec3) -> Vec3 {
        self.direction(p) * self.units.per_metre()
    }

    /// A direction (a normal, say) of the engine in the file's axes, unscaled.
    #[inline]
    pub fn direction(&self, d: &Vec3) -> Vec3 {
        match self.up {
            UpAxis::Z => *d,
            UpAxis::Y => Vec3::new(d.x, d.z, -d.y),
        }
    }

    /// A point of the file back in the engine's frame (metres, +Z up).
    #[inline]
    pub fn to_engine(&self, p: &Vec3) -> Vec3 {
        let q = p / self.units.per_metre();
        match self.up {
            UpAxis::Z => q,
            UpAxis::Y => Vec3::new(q.x, -q.z, q.y),
        }
    }

    /// A one-line description for a file comment, e.g. `+Y up, metres`.
    pub fn describe(&self) -> String {
        let up = match self.up {
            UpAxis::Y => "+Y up",
            UpAxis::Z => "+Z up",
        };
        format!("{up}, units {}", self.units.symbol())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn y_up_turns_the_engine_up_into_plus_y_and_keeps_handedness() {
        let f = ExportFrame::Y_UP_METRES;
        assert_eq!(f.direction(&Vec3::z()), Vec3::y());
        assert_eq!(f.direction(&Vec3::x()), Vec3::x());
        // the front of a mannequin (engine −Y) faces glTF's +Z
        assert_eq!(f.direction(&-Vec3::y()), Vec3::z());
        // a rotation: x × y = z holds in the file too
        let (x, y, z) = (
            f.direction(&Vec3::x()),
            f.direction(&Vec3::y()),
            f.direction(&Vec3::z()),
        );
        assert_eq!(x.cross(&y), z);
    }

    #[test]
    fn units_scale_and_round_trip_exactly_in_metres() {
        let p = Vec3::new(0.1, -0.87, 1.05);
        let mm = ExportFrame {
            up: UpAxis::Y,
            units: Units::Millimetres,
        };
        let q = mm.point(&p);
        assert!((q - Vec3::new(100.0, 1050.0, 870.0)).norm() < 1e-9);
        assert!((mm.to_engine(&q) - p).norm() < 1e-15);
        let m = ExportFrame::Y_UP_METRES;
        assert_eq!(m.to_engine(&m.point(&p)), p);
        assert_eq!(Units::parse("cm"), Ok(Units::Centimetres));
        assert!(Units::parse("inch").is_err());
        assert!(UpAxis::parse("x").is_err());
    }
}
