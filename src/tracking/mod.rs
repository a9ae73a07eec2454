//! Tracking: camera calibration, the tracking puppet and its joints, synthetic multi-camera
//! sequences with ground truth, and the analysis-by-synthesis body tracker. The camera model
//! is [`crate::geometry::Camera`]; images are drawn by [`crate::render::raster`].
//!
//! - [`correspondences`]: checks of 3D–2D correspondences and the calibration error;
//! - [`dlt`]: linear resection (normalised DLT) and the RQ split of a projection matrix;
//! - [`calibration`]: camera calibration from 3D–2D correspondences (DLT, then
//!   Levenberg–Marquardt refinement of intrinsics, distortion and pose);
//! - [`joints`]: the sixteen tracking joints on the MakeHuman skeleton, and the error measure;
//! - [`puppet`], [`puppet_mesh`]: the tracking puppet (pose parameters with joint limits,
//!   forward kinematics onto the MakeHuman skeleton) and its light mesh for rendering;
//! - [`clothing`], [`sequence`], [`sequence_render`], [`sequence_files`]: synthetic
//!   multi-camera sequences with ground truth, and reading any sequence folder;
//!   [`sequence_dressing`]: real garments sewn on the person and simulated through the motion;
//! - [`golf_sequence`], [`club_mesh`]: broadcast sequences of a captured golf swing;
//!   [`golf_track`]: the tracked swing's golf metrics against the truth;
//! - [`pyramid`], [`texture`], [`cost`], [`annealing`], [`restarts`], [`tracker`]: the tracker;
//! - [`visual_hull`], [`auto_start`], [`loss`]: finding the person without help (the
//!   automatic start), noticing a lost track and finding the body again; [`body_adapt`]: the
//!   puppet's proportions fitted to the person at the start;
//! - [`bvh_export`], [`overlay`], [`swing_metrics`], [`track_outputs`]: its outputs.

pub mod address_pose;
pub mod annealing;
pub mod auto_start;
pub mod background_model;
pub mod body_adapt;
pub mod bvh_export;
pub mod calibration;
pub mod checkpoint;
pub mod clothing;
pub mod club;
mod club_evidence;
pub mod club_mesh;
mod club_path;
pub mod club_track;
pub mod correspondences;
pub mod cost;
pub mod dlt;
pub mod frame_status;
pub mod golf_metrics;
pub mod golf_motion;
pub mod golf_sequence;
pub mod golf_track;
pub mod golf_trial;
pub mod hands_prior;
pub mod joints;
pub mod loss;
pub mod marker_fit;
pub mod marker_set;
pub mod overlay;
pub mod puppet;
pub mod puppet_mesh;
pub mod pyramid;
pub mod restarts;
pub mod sequence;
pub mod sequence_dressing;
pub mod sequence_files;
pub mod sequence_options;
pub mod sequence_render;
pub mod sequence_run;
pub mod stage_cost;
pub mod swing_metrics;
pub mod texture;
pub mod track_outputs;
pub mod tracker;
pub mod tracker_options;
pub mod visual_hull;
