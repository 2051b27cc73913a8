//! The scene a request names: its mesh and its camera.

use std::path::Path;

use render::{Camera, Mesh, Scene};

use crate::{Error, Request};

/// The mesh `name` names: `sphere` (the unit UV sphere every preview, test and benchmark shows),
/// `torus`, or the path of a Wavefront OBJ file (scaled to the unit sphere; a regular file only,
/// its size checked against [`Mesh::MAX_OBJ_BYTES`] before it is read).
pub fn mesh(name: &str) -> Result<Mesh, Error> {
    Ok(match name {
        "sphere" => Mesh::sphere(1.0, 128, 64),
        "torus" => Mesh::torus(0.7, 0.3, 128, 48),
        path => {
            let bytes = fsguard::read_regular(Path::new(path), Mesh::MAX_OBJ_BYTES as u64)
                .map_err(|e| Error::Invalid(format!("reading {path}: {e}")))?;
            let text = String::from_utf8(bytes)
                .map_err(|_| Error::Invalid(format!("reading {path}: not utf-8 text (an obj file)")))?;
            Mesh::from_obj(&text).map_err(|e| Error::Invalid(format!("reading {path}: {e}")))?
        }
    })
}

/// The scene the request describes.
pub(crate) fn scene(request: &Request) -> Result<Scene, Error> {
    let mesh = mesh(&request.mesh)?;
    let default = Camera::default();
    let (azimuth, elevation) = request.camera;
    let camera = Camera::orbit(
        default.target(),
        default.distance(),
        azimuth.to_radians(),
        elevation.to_radians(),
        default.fov_y(),
    )
    .map_err(|e| Error::Invalid(format!("--camera: {e}")))?;
    Ok(Scene { mesh, camera, width: request.size.0, height: request.size.1 })
}
