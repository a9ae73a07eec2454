//! Built-in software rendering, so a user sees a result without another tool, and the
//! rasterizer of the vision code:
//!
//! - [`picture`]: smooth-shaded, supersampled pictures of [`RenderMesh`]es seen by a
//!   [`LookAtCamera`](crate::geometry::LookAtCamera), as an RGB image or a PNG file;
//! - [`raster`]: the z-buffered vertex-colour rasterizer (depth and interpolated colours or
//!   texture coordinates) that the body tracker, its synthetic sequences and the face code
//!   draw through a calibrated [`Camera`](crate::geometry::Camera);
//! - [`plot`]: line plots;
//! - [`animated_png`]: animations a browser plays (APNG);
//! - [`shadow`]: the area of a mesh's shadow on the ground (a drape coefficient's measure).

pub mod animated_png;
pub mod picture;
pub mod plot;
pub mod raster;
mod shading;
pub mod shadow;

pub use picture::{render, render_png, RenderMesh};
pub use plot::{
    write_plot, write_plot_pair, write_series_csv, PlotError, PlotSpec, Series, SeriesStyle,
};
pub use raster::{draw_triangles, project_vertices, RasterTarget};
