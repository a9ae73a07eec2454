//! The learned facade parse: a random forest classifies every pixel of a photo into facade
//! elements ([`classes`]: window, door, wall, balcony, shop, ledge, sky, other) from colour,
//! texture, position and repetition features ([`features`], [`forest`]); structure then
//! corrects it ([`rectangles`]: windows as rectangles aligned by floor and column, missing
//! windows of the lattice filled, doors at street level). Training ([`train`]) reads the
//! labelled folders ([`dataset`]: CMP Facade index labels or LabelMeFacade colour labels)
//! and writes a versioned model file ([`model`]) at run time; [`photo_parse`] parses one
//! photo and [`evaluate`] scores a folder.

pub mod classes;
pub mod dataset;
pub mod evaluate;
pub mod features;
pub mod forest;
pub mod model;
pub mod photo_parse;
pub mod rectangles;
pub mod train;
