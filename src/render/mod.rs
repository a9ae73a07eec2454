//! Built-in software rendering, so a user sees a result without another tool: a pinhole
//! [`Camera`] (with automatic framing of a bounding box) and a z-buffered, smooth-shaded
//! triangle rasterizer that draws [`RenderMesh`]es into an RGB image or a PNG file.

pub mod camera;
pub mod plot;
pub mod raster;
mod shading;

pub use camera::Camera;
pub use plot::{
    write_plot, write_plot_pair, write_series_csv, PlotError, PlotSpec, Series, SeriesStyle,
};
pub use raster::{render, render_png, RenderMesh};
