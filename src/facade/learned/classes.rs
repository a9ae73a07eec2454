//! The element classes the learned facade classifier tells apart, and how the two datasets'
//! labels map onto them and back: CMP Facade index labels (1 background … 12 shop) and
//! LabelMeFacade colour labels (building, window, door, sky, …).

use super::super::labels::Class;

/// Number of element classes.
pub const N_CLASSES: usize = 8;

/// A facade element class of the learned classifier.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Element {
    /// Window glass and frame (CMP blinds count as window).
    Window,
    /// Door.
    Door,
    /// Wall (CMP facade, deco and pillar; LabelMeFacade building).
    Wall,
    /// Balcony.
    Balcony,
    /// Shop front.
    Shop,
    /// Cornice, sill or molding: the horizontal ledges.
    Ledge,
    /// Sky and what lies beyond the facade (CMP background).
    Sky,
    /// Vegetation, cars, road, pavement and anything else.
    Other,
}

/// CMP Facade palette (index 0 unused, 1 background … 12 shop), as the dataset's PNGs carry it.
pub const CMP_PALETTE: [[u8; 3]; 13] = [
    [0, 0, 0],
    [0, 0, 170],
    [0, 0, 255],
    [0, 85, 255],
    [0, 170, 255],
    [0, 255, 255],
    [85, 255, 170],
    [170, 255, 85],
    [255, 255, 0],
    [255, 170, 0],
    [255, 85, 0],
    [255, 0, 0],
    [170, 0, 0],
];

impl Element {
    /// All classes, in index order.
    pub const ALL: [Element; N_CLASSES] = [
        Element::Window,
        Element::Door,
        Element::Wall,
        Element::Balcony,
        Element::Shop,
        Element::Ledge,
        Element::Sky,
        Element::Other,
    ];

    /// Index in [`Element::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }

    /// The class of an index below [`N_CLASSES`] (others are `Other`).
    pub fn from_index(i: usize) -> Element {
        Element::ALL.get(i).copied().unwrap_or(Element::Other)
    }

    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Element::Window => "window",
            Element::Door => "door",
            Element::Wall => "wall",
            Element::Balcony => "balcony",
            Element::Shop => "shop",
            Element::Ledge => "ledge",
            Element::Sky => "sky",
            Element::Other => "other",
        }
    }

    /// The class of a CMP Facade label index (1 background, 2 facade, 3 window, 4 door,
    /// 5 cornice, 6 sill, 7 balcony, 8 blind, 9 deco, 10 molding, 11 pillar, 12 shop).
    pub fn from_cmp(index: u8) -> Option<Element> {
        Some(match index {
            1 => Element::Sky,
            2 | 9 | 11 => Element::Wall,
            3 | 8 => Element::Window,
            4 => Element::Door,
            5 | 6 | 10 => Element::Ledge,
            7 => Element::Balcony,
            12 => Element::Shop,
            _ => return None,
        })
    }

    /// The CMP label index written for this class.
    pub fn to_cmp(self) -> u8 {
        match self {
            Element::Sky | Element::Other => 1,
            Element::Wall => 2,
            Element::Window => 3,
            Element::Door => 4,
            Element::Ledge => 5,
            Element::Balcony => 7,
            Element::Shop => 12,
        }
    }

    /// The class of a LabelMeFacade colour: building → wall, sky → sky; various, car,
    /// vegetation, pavement and road → other.
    pub fn from_labelmefacade(rgb: [u8; 3]) -> Option<Element> {
        Some(match rgb {
            [0, 0, 128] => Element::Window,
            [128, 0, 0] => Element::Wall,
            [128, 128, 0] => Element::Door,
            [0, 128, 128] => Element::Sky,
            [0, 0, 0] | [128, 0, 128] | [0, 128, 0] | [128, 128, 128] | [128, 64, 0] => {
                Element::Other
            }
            _ => return None,
        })
    }

    /// The LabelMeFacade colour written for this class: the classes that dataset lacks
    /// (balcony, shop, ledge) are building, other is "various".
    pub fn to_labelmefacade(self) -> [u8; 3] {
        match self {
            Element::Window => [0, 0, 128],
            Element::Door => [128, 128, 0],
            Element::Wall | Element::Balcony | Element::Shop | Element::Ledge => [128, 0, 0],
            Element::Sky => [0, 128, 128],
            Element::Other => [0, 0, 0],
        }
    }

    /// The canonical scoring class of a ground-truth pixel: shop → door (an opening),
    /// ledge → wall, sky → background, other → ignore.
    pub fn canonical_truth(self) -> Class {
        match self {
            Element::Window => Class::Window,
            Element::Door | Element::Shop => Class::Door,
            Element::Wall | Element::Ledge => Class::Wall,
            Element::Balcony => Class::Balcony,
            Element::Sky => Class::Background,
            Element::Other => Class::Ignore,
        }
    }

    /// The canonical scoring class of a predicted pixel: as [`Element::canonical_truth`],
    /// except that a prediction of other is background (a prediction is never ignored).
    pub fn canonical_pred(self) -> Class {
        match self {
            Element::Other => Class::Background,
            e => e.canonical_truth(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dataset_labels_round_trip_through_the_elements() {
        for i in 1..=12u8 {
            let e = Element::from_cmp(i).unwrap();
            assert_eq!(Element::from_cmp(e.to_cmp()), Some(e), "cmp {i}");
        }
        assert_eq!(Element::from_cmp(0), None);
        assert_eq!(Element::from_cmp(13), None);
        for e in Element::ALL {
            assert_eq!(Element::from_index(e.index()), e);
            let back = Element::from_labelmefacade(e.to_labelmefacade()).unwrap();
            match e {
                Element::Balcony | Element::Shop | Element::Ledge => {
                    assert_eq!(back, Element::Wall)
                }
                _ => assert_eq!(back, e),
            }
        }
    }
}
