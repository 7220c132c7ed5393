//! The film: what a camera sample leaves in a pixel besides its colour. The pixel filter
//! (`filter`), adaptive sampling's per-pixel error (`adaptive`), the denoiser's albedo and
//! normal features (`denoise_features`), optical flow (`flow`) and the view layer's shader
//! AOV passes (`aov`).

pub mod adaptive;
pub mod aov;
pub mod denoise_features;
pub mod filter;
pub mod flow;
