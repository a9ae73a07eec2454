//! Facades: reconstruction of building facades from photos (Müller, Zeng, Wonka & Van Gool
//! 2007) and its evaluation against labelled photos. The pipeline ([`analysis`]): photo →
//! rectification ([`segments`], [`vanishing`], [`homography`]) → floors and tiles by mutual
//! information ([`mutual_information`], [`repetition`]) → the irreducible tile and its window
//! ([`parse`], found as a [`parse_structure`]), windows one by one ([`window_blobs`],
//! [`window_grammar`]) → their frames and sills ([`tile_refinement`], [`refinement`]) → the
//! shape grammar ([`grammar`], [`parse_grammar`]) with the library element the windows look
//! like ([`element_library`], [`element_match`]) → outputs ([`outputs`]: overlays
//! ([`overlay`]), rule files, 3D facades ([`facade_mesh`], [`facade_export`])). The
//! evaluation: label maps in canonical classes ([`labels`]), derived grammars back as pixels
//! ([`rasterize`]), window instances ([`instances`]), pixel and window-detection scores
//! ([`score`], protocol of `facade-reconstruction.md` §4) and folder reports ([`report`]).
//! Photos are read as the grey images of [`crate::geometry::image`].

pub mod analysis;
pub mod assignment;
pub mod element_library;
pub mod element_match;
pub mod error;
pub mod facade_export;
pub mod facade_mesh;
pub mod grammar;
pub mod homography;
pub mod instances;
pub mod labels;
pub mod learned;
pub mod mutual_information;
pub mod outputs;
pub mod overlay;
pub mod parse;
pub mod parse_grammar;
pub mod parse_structure;
pub mod rasterize;
pub mod rect;
pub mod refinement;
pub mod repetition;
pub mod report;
pub mod rule_file;
pub mod score;
pub mod segments;
pub mod structure;
pub mod tile_refinement;
pub mod vanishing;
pub mod window_blobs;
pub mod window_grammar;

pub use error::FacadeError;
pub use labels::{Class, LabelMap};
pub use rect::Rect;
pub use report::{FacadeParse, ImageReport, Summary};
pub use score::{DetectionScore, FacadeScore, PixelScore};
