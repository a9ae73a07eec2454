//! Images and their filters, once for the vision modules: the grey image type ([`Gray`], 8-bit
//! or float), the float grey image with its gradients that photometric fitting samples
//! ([`GradientImage`]), linear filters (blurs, box mean, Sobel and central-difference
//! gradients, 2×2 downsampling: [`filters`]), binary morphology ([`morphology`]) and connected
//! components ([`components`](mod@components)), and the photo formats read everywhere
//! ([`photo_formats`]). Each is written once here, as the vision
//! modules had it, so their figures stay the same (`imageproc` was measured against each: see
//! the modules).

pub mod components;
pub mod filters;
pub mod gradient_image;
pub mod gray;
pub mod morphology;
pub mod photo_formats;

pub use components::{components, Component, Connectivity};
pub use gradient_image::GradientImage;
pub use gray::{luma, read_rgb, Gray};
pub use photo_formats::{
    check_image_file, check_pixels, is_photo, photo_files, photo_with_stem, photo_with_stem_or,
    read_photo, PHOTO_EXTENSIONS,
};
