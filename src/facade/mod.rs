//! Facades: reconstruction of building facades from photos (Müller, Zeng, Wonka & Van Gool
//! 2007), and its evaluation against labelled photos. So far: the evaluation — label maps in
//! canonical classes ([`labels`]), window instances of a label map ([`instances`]), the pixel
//! and window-detection scores of a prediction ([`score`], protocol of
//! `facade-reconstruction.md` §4) and folder reports ([`report`]); and the first analysis
//! stage — grayscale photos ([`gray`]), mutual information of image bands
//! ([`mutual_information`]) and the floor and tile repetition it reveals ([`repetition`]).

pub mod assignment;
pub mod error;
pub mod grammar;
pub mod gray;
pub mod homography;
pub mod instances;
pub mod labels;
pub mod mutual_information;
pub mod parse;
pub mod rect;
pub mod repetition;
pub mod report;
pub mod score;
pub mod structure;

pub use error::FacadeError;
pub use labels::{Class, LabelMap};
pub use rect::Rect;
pub use report::{FacadeParse, ImageReport, Summary};
pub use score::{DetectionScore, FacadeScore, PixelScore};
