//! Label maps in the canonical facade classes of the evaluation protocol
//! (`facade-reconstruction.md` §4.1): window, wall, door, balcony, background, and ignore for
//! what no facade parse is asked to explain (cars, trees, road…). Readers map each dataset's
//! colour coding onto them.

use std::path::Path;

use super::error::FacadeError;
use super::rect::Rect;

/// A canonical facade class.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Class {
    /// Window (glass and frame).
    Window,
    /// Wall (the facade's surface).
    Wall,
    /// Door or shop opening.
    Door,
    /// Balcony.
    Balcony,
    /// Sky, roof: not facade.
    Background,
    /// Occluders and unlabelled pixels: scored as neither right nor wrong.
    Ignore,
}

impl Class {
    /// The scored classes, in confusion-matrix order.
    pub const SCORED: [Class; 5] = [
        Class::Window,
        Class::Wall,
        Class::Door,
        Class::Balcony,
        Class::Background,
    ];

    /// Index in [`Class::SCORED`] (`None` for ignore).
    pub fn index(self) -> Option<usize> {
        Class::SCORED.iter().position(|c| *c == self)
    }

    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Class::Window => "window",
            Class::Wall => "wall",
            Class::Door => "door",
            Class::Balcony => "balcony",
            Class::Background => "background",
            Class::Ignore => "ignore",
        }
    }

    /// The class of a lower-case name.
    pub fn from_name(s: &str) -> Option<Class> {
        [Class::Ignore]
            .into_iter()
            .chain(Class::SCORED)
            .find(|c| c.name() == s)
    }

    /// The LabelMeFacade class of an RGB colour (colour map of the dataset's README), mapped
    /// to the canonical classes: building → wall, sky → background; various, car, vegetation,
    /// pavement, road → ignore.
    pub fn from_labelmefacade(rgb: [u8; 3]) -> Option<Class> {
        Some(match rgb {
            [0, 0, 128] => Class::Window,
            [128, 0, 0] => Class::Wall,
            [128, 128, 0] => Class::Door,
            [0, 128, 128] => Class::Background,
            [0, 0, 0] | [128, 0, 128] | [0, 128, 0] | [128, 128, 128] | [128, 64, 0] => {
                Class::Ignore
            }
            _ => return None,
        })
    }
}

/// A class per pixel, row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct LabelMap {
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Class of pixel (x, y) at `y · width + x`.
    pub classes: Vec<Class>,
}

impl LabelMap {
    /// A map of one class.
    pub fn filled(width: u32, height: u32, class: Class) -> Self {
        LabelMap {
            width,
            height,
            classes: vec![class; width as usize * height as usize],
        }
    }

    /// Reads a LabelMeFacade label map (PNG, RGB or RGBA). Every pixel must carry one of the
    /// dataset's nine colours; the first that does not is named with the file.
    pub fn read_labelmefacade(path: &Path) -> Result<Self, FacadeError> {
        let img = crate::geometry::image::read_rgb(path)?;
        let (width, height) = img.dimensions();
        let mut classes = Vec::with_capacity(width as usize * height as usize);
        for (x, y, p) in img.enumerate_pixels() {
            let rgb = p.0;
            let c = Class::from_labelmefacade(rgb).ok_or(FacadeError::UnknownColour {
                path: path.to_path_buf(),
                x,
                y,
                rgb,
            })?;
            classes.push(c);
        }
        Ok(LabelMap {
            width,
            height,
            classes,
        })
    }

    /// Class at (x, y).
    pub fn at(&self, x: u32, y: u32) -> Class {
        self.classes[y as usize * self.width as usize + x as usize]
    }

    /// Sets the pixels of `r` (clipped to the map) to `class`.
    pub fn paint(&mut self, r: &Rect, class: Class) {
        for y in r.y0..r.y1.min(self.height) {
            for x in r.x0..r.x1.min(self.width) {
                self.classes[y as usize * self.width as usize + x as usize] = class;
            }
        }
    }

    /// Pixels of `class`.
    pub fn count(&self, class: Class) -> usize {
        self.classes.iter().filter(|c| **c == class).count()
    }

    /// Pixels of `class` inside `r`.
    pub fn count_in(&self, r: &Rect, class: Class) -> u64 {
        let mut n = 0;
        for y in r.y0..r.y1.min(self.height) {
            for x in r.x0..r.x1.min(self.width) {
                n += (self.at(x, y) == class) as u64;
            }
        }
        n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_labelmefacade_colour_maps_and_others_do_not() {
        let known = [
            [0, 0, 0],
            [128, 0, 0],
            [128, 0, 128],
            [128, 128, 0],
            [128, 128, 128],
            [128, 64, 0],
            [0, 128, 128],
            [0, 128, 0],
            [0, 0, 128],
        ];
        for c in known {
            assert!(Class::from_labelmefacade(c).is_some(), "{c:?}");
        }
        assert_eq!(Class::from_labelmefacade([0, 0, 128]), Some(Class::Window));
        assert_eq!(Class::from_labelmefacade([128, 0, 0]), Some(Class::Wall));
        assert_eq!(Class::from_labelmefacade([1, 0, 128]), None);
        for c in Class::SCORED {
            assert_eq!(Class::from_name(c.name()), Some(c));
        }
    }
}
