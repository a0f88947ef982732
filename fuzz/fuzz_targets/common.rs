//! What every mesh target does with a reader's result: a mesh that reads and validates is healed and
//! integrated too (the path a real file takes). A panic anywhere aborts the run (libfuzzer-sys's panic
//! hook), even where the library would catch it, so caught panics are found as well.

use std::path::Path;
use urdf_inertia::mesh::{self, MeshError, MeshErrorKind, RawMesh};

pub fn heal(result: Result<RawMesh, MeshError>, path: &Path) {
    let Ok(raw) = result else { return };
    if mesh::validate(&raw, path).is_err() {
        return;
    }
    for scale in [[1.0; 3], [1.0, -1.0, 1.0]] {
        if let Err(e) = mesh::solid_from_raw(&raw, scale, path, Default::default()) {
            assert!(
                !matches!(e.kind, MeshErrorKind::Internal(_)),
                "healing failed internally: {e}"
            );
        }
    }
}
