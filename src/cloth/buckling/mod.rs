//! Buckling: what a compressed cloth does instead of staying compressed. Choi & Ko's
//! immediate-buckling response and its arc connections with the side each buckles to, the
//! compression-release model, and the measures of wrinkles and of springs left compressed.

pub mod arc_connection;
pub mod buckling_side;
pub mod choi_ko;
pub mod compression_release;
pub mod wrinkles;
