//! Images and their filters, once for the vision modules: the grey image type ([`Gray`], 8-bit
//! or float), the float grey image with its gradients that photometric fitting samples
//! ([`GradientImage`]), linear filters (blurs, box mean, Sobel and central-difference
//! gradients, 2×2 downsampling: [`filters`]), binary morphology ([`morphology`]) and connected
//! components ([`components`]). Filters run on `imageproc` where it gives the same numbers as
//! the kernels the modules had; the others are written here once.

pub mod components;
pub mod filters;
pub mod gradient_image;
pub mod gray;
pub mod morphology;

pub use components::{components, Component, Connectivity};
pub use gradient_image::GradientImage;
pub use gray::{luma, read_rgb, Gray};
