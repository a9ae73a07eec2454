//! Placement of a meshed garment around a mannequin before sewing: the body's own frame
//! ([`body_frame`]) and silhouettes ([`silhouette`]), the figurine planes the pieces are laid
//! on, the rows wrapped on convex shells ([`shell`]), the pieces that go over the shoulders,
//! centre seams, layers of overlapping pieces, and the multi-resolution relaxation that ends
//! automatic pre-positioning ([`preposition`]).

pub mod body_frame;
mod centre_seams;
mod figurine;
mod hierarchy;
mod layers;
mod over_the_top;
pub mod preposition;
mod relax;
mod rows;
pub mod shell;
pub mod silhouette;
