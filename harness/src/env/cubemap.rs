//! The cube map of an environment lives in core (`steradian_core::rsl::cubemap`, where the
//! decomposition needs it); the harness loads files into it (`hdr`, `sky`).

pub use steradian_core::rsl::cubemap::{
    CubeMap, DEFAULT_N, FACES, dir_to_face, face_dir, for_each_sub_texel, rect_solid_angle,
};
