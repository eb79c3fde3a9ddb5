//! Pictures of where the complexity is: the scene drawn from a camera with each patch coloured by a
//! per-patch quantity of a run ([`crate::PatchResult`]), and the coloured mesh as PLY.
//!
//! * [`camera`]: the pinhole camera and the default view (inside a room when the scene is one);
//! * [`image`]: first-hit rays through the camera, traced by the run's own tracer, and the picture's
//!   pixels (shaded by the viewing angle, back sides grey, patch outlines darkened);
//! * [`colour`]: the quantities and the viridis colour scale;
//! * [`bar`]: the colour bar's labels, both ends and round ticks;
//! * [`title`]: the title fitted to the picture's width;
//! * [`ply`]: the mesh with a colour per patch;
//! * [`noise`]: whether the colours are mostly noise, and the lines that would fix it.

pub mod bar;
pub mod camera;
pub mod colour;
pub mod image;
pub mod noise;
pub mod ply;
pub mod title;

pub use bar::{bar_labels, BarLabel};
pub use camera::{default_camera, view_score, Camera, CameraError, ViewScore};
pub use colour::{ColourScale, Quantity, Tick, NO_DATA};
pub use image::{trace_view, PatchImage, Sample, BACKGROUND, BACK_SIDE};
pub use noise::{noise_summary, NoiseSummary};
pub use ply::{write_ply, PlyFormat};
pub use title::{fit_title, TitleLayout, TitleParts};
