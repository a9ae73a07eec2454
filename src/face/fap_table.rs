//! The FAP table of [`super::FapRig`]: per FAP its MPEG-4 number and name, unit, feature
//! point(s) on the MediaPipe mesh, direction, zone radius and range; and which side of the
//! mouth or of an eye each lip or eyelid FAP stays on.

use super::zone::{
    LEFT_LOWER_LID, LEFT_UPPER_LID, LOWER_INNER_LIP, RIGHT_LOWER_LID, RIGHT_UPPER_LID,
    UPPER_INNER_LIP,
};
use super::FapUnit;

/// Which vertices carry a FAP.
#[derive(Clone, Copy, Debug)]
pub(super) enum Seeds {
    /// These vertices move together along the FAP direction; the first is the feature point.
    Points(&'static [usize]),
    /// The lower jaw: chin 152, weight 1 out to the lower inner lip.
    Jaw,
    /// An eyelid rim: (upper rim, lower rim, index of the feature point in them).
    Lid(&'static [usize; 7], &'static [usize; 7]),
}

/// Table entry: number, name, unit, seeds, direction, zone radius (× ES), range.
pub(super) struct Spec(
    pub u8,
    pub &'static str,
    pub FapUnit,
    pub Seeds,
    pub [f64; 3],
    pub f64,
    pub (f64, f64),
);

use super::FapUnit::{Ens, Es, Irisd, Mns, Mw};
use Seeds::{Jaw, Lid, Points};

/// The FAPs of the rig. Left (`_l_`) FAPs on +x vertices, right ones on their mirrors.
pub(super) const SPECS: &[Spec] = &[
    Spec(
        3,
        "open_jaw",
        Mns,
        Jaw,
        [0.0, -1.0, 0.0],
        0.45,
        (0.0, 1000.0),
    ),
    Spec(
        4,
        "lower_t_midlip",
        Mns,
        Points(&[13, 0]),
        [0.0, -1.0, 0.0],
        0.3,
        (-300.0, 300.0),
    ),
    Spec(
        5,
        "raise_b_midlip",
        Mns,
        Points(&[14, 17]),
        [0.0, 1.0, 0.0],
        0.3,
        (-300.0, 300.0),
    ),
    Spec(
        6,
        "stretch_l_cornerlip",
        Mw,
        Points(&[291, 308]),
        [1.0, 0.0, 0.0],
        0.4,
        (-200.0, 200.0),
    ),
    Spec(
        7,
        "stretch_r_cornerlip",
        Mw,
        Points(&[61, 78]),
        [-1.0, 0.0, 0.0],
        0.4,
        (-200.0, 200.0),
    ),
    Spec(
        8,
        "lower_t_lip_lm",
        Mns,
        Points(&[311, 269]),
        [0.0, -1.0, 0.0],
        0.25,
        (-300.0, 300.0),
    ),
    Spec(
        9,
        "lower_t_lip_rm",
        Mns,
        Points(&[81, 39]),
        [0.0, -1.0, 0.0],
        0.25,
        (-300.0, 300.0),
    ),
    Spec(
        10,
        "raise_b_lip_lm",
        Mns,
        Points(&[402, 405]),
        [0.0, 1.0, 0.0],
        0.25,
        (-300.0, 300.0),
    ),
    Spec(
        11,
        "raise_b_lip_rm",
        Mns,
        Points(&[178, 181]),
        [0.0, 1.0, 0.0],
        0.25,
        (-300.0, 300.0),
    ),
    Spec(
        12,
        "raise_l_cornerlip",
        Mns,
        Points(&[291, 308]),
        [0.0, 1.0, 0.0],
        0.4,
        (-400.0, 400.0),
    ),
    Spec(
        13,
        "raise_r_cornerlip",
        Mns,
        Points(&[61, 78]),
        [0.0, 1.0, 0.0],
        0.4,
        (-400.0, 400.0),
    ),
    Spec(
        14,
        "thrust_jaw",
        Mns,
        Jaw,
        [0.0, 0.0, 1.0],
        0.45,
        (-150.0, 300.0),
    ),
    Spec(
        15,
        "shift_jaw",
        Mw,
        Jaw,
        [-1.0, 0.0, 0.0],
        0.45,
        (-200.0, 200.0),
    ),
    Spec(
        16,
        "push_b_lip",
        Mns,
        Points(&[14, 17]),
        [0.0, 0.0, 1.0],
        0.3,
        (-300.0, 300.0),
    ),
    Spec(
        17,
        "push_t_lip",
        Mns,
        Points(&[13, 0]),
        [0.0, 0.0, 1.0],
        0.3,
        (-300.0, 300.0),
    ),
    Spec(
        19,
        "close_t_l_eyelid",
        Irisd,
        Lid(&LEFT_UPPER_LID, &LEFT_LOWER_LID),
        [0.0, -1.0, 0.0],
        0.25,
        (0.0, 0.0),
    ),
    Spec(
        20,
        "close_t_r_eyelid",
        Irisd,
        Lid(&RIGHT_UPPER_LID, &RIGHT_LOWER_LID),
        [0.0, -1.0, 0.0],
        0.25,
        (0.0, 0.0),
    ),
    Spec(
        21,
        "close_b_l_eyelid",
        Irisd,
        Lid(&LEFT_LOWER_LID, &LEFT_UPPER_LID),
        [0.0, 1.0, 0.0],
        0.2,
        (0.0, 0.0),
    ),
    Spec(
        22,
        "close_b_r_eyelid",
        Irisd,
        Lid(&RIGHT_LOWER_LID, &RIGHT_UPPER_LID),
        [0.0, 1.0, 0.0],
        0.2,
        (0.0, 0.0),
    ),
    Spec(
        31,
        "raise_l_i_eyebrow",
        Ens,
        Points(&[336, 285]),
        [0.0, 1.0, 0.0],
        0.45,
        (-150.0, 250.0),
    ),
    Spec(
        32,
        "raise_r_i_eyebrow",
        Ens,
        Points(&[107, 55]),
        [0.0, 1.0, 0.0],
        0.45,
        (-150.0, 250.0),
    ),
    Spec(
        33,
        "raise_l_m_eyebrow",
        Ens,
        Points(&[334, 282]),
        [0.0, 1.0, 0.0],
        0.45,
        (-150.0, 250.0),
    ),
    Spec(
        34,
        "raise_r_m_eyebrow",
        Ens,
        Points(&[105, 52]),
        [0.0, 1.0, 0.0],
        0.45,
        (-150.0, 250.0),
    ),
    Spec(
        35,
        "raise_l_o_eyebrow",
        Ens,
        Points(&[300, 276]),
        [0.0, 1.0, 0.0],
        0.45,
        (-150.0, 250.0),
    ),
    Spec(
        36,
        "raise_r_o_eyebrow",
        Ens,
        Points(&[70, 46]),
        [0.0, 1.0, 0.0],
        0.45,
        (-150.0, 250.0),
    ),
    Spec(
        37,
        "squeeze_l_eyebrow",
        Es,
        Points(&[336, 285]),
        [-1.0, 0.0, 0.0],
        0.3,
        (-80.0, 100.0),
    ),
    Spec(
        38,
        "squeeze_r_eyebrow",
        Es,
        Points(&[107, 55]),
        [1.0, 0.0, 0.0],
        0.3,
        (-80.0, 100.0),
    ),
    Spec(
        39,
        "puff_l_cheek",
        Es,
        Points(&[411]),
        [1.0, 0.0, 0.0],
        0.45,
        (0.0, 150.0),
    ),
    Spec(
        40,
        "puff_r_cheek",
        Es,
        Points(&[187]),
        [-1.0, 0.0, 0.0],
        0.45,
        (0.0, 150.0),
    ),
    Spec(
        41,
        "lift_l_cheek",
        Ens,
        Points(&[347]),
        [0.0, 1.0, 0.0],
        0.35,
        (0.0, 200.0),
    ),
    Spec(
        42,
        "lift_r_cheek",
        Ens,
        Points(&[118]),
        [0.0, 1.0, 0.0],
        0.35,
        (0.0, 200.0),
    ),
    Spec(
        61,
        "stretch_l_nose",
        Ens,
        Points(&[358]),
        [1.0, 0.0, 0.0],
        0.15,
        (-50.0, 80.0),
    ),
    Spec(
        62,
        "stretch_r_nose",
        Ens,
        Points(&[129]),
        [-1.0, 0.0, 0.0],
        0.15,
        (-50.0, 80.0),
    ),
    Spec(
        63,
        "raise_nose",
        Ens,
        Points(&[4]),
        [0.0, 1.0, 0.0],
        0.3,
        (-50.0, 100.0),
    ),
];

/// Half-width of the side masks' ramp at the mouth and eye corners (× ES).
pub(super) const SIDE_RAMP: f64 = 0.02;

/// The rim a FAP belongs to and the facing rim it must not move: lower-lip and jaw FAPs,
/// upper-lip FAPs, each eyelid. `None` for the lip corners and the rest.
pub(super) fn side(number: u8) -> Option<(&'static [usize], &'static [usize])> {
    match number {
        3 | 5 | 10 | 11 | 14 | 15 | 16 => Some((&LOWER_INNER_LIP, &UPPER_INNER_LIP)),
        4 | 8 | 9 | 17 => Some((&UPPER_INNER_LIP, &LOWER_INNER_LIP)),
        19 => Some((&LEFT_UPPER_LID, &LEFT_LOWER_LID)),
        20 => Some((&RIGHT_UPPER_LID, &RIGHT_LOWER_LID)),
        21 => Some((&LEFT_LOWER_LID, &LEFT_UPPER_LID)),
        22 => Some((&RIGHT_LOWER_LID, &RIGHT_UPPER_LID)),
        _ => None,
    }
}

/// Index of the mid-lid vertex (the feature point) in the lid rim arrays.
pub(super) const MID_LID: usize = 3;
