//! Facades: reconstruction of building facades from photos (Müller, Zeng, Wonka & Van Gool
//! 2007), and its evaluation against labelled photos. So far this module holds the evaluation:
//! label maps in canonical classes ([`labels`]), window instances of a label map
//! ([`instances`]), and the pixel and window-detection scores of a prediction ([`score`]), as
//! the protocol of `facade-reconstruction.md` §4 defines them.

pub mod assignment;
pub mod error;
pub mod instances;
pub mod labels;
pub mod rect;
pub mod report;
pub mod score;

pub use error::FacadeError;
pub use labels::{Class, LabelMap};
pub use rect::Rect;
pub use report::{FacadeParse, ImageReport, Summary};
pub use score::{DetectionScore, FacadeScore, PixelScore};
