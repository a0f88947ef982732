//! The model for meshes that do not close (`--open-mesh`): what stands for the solid when flat caps
//! over the holes cannot be trusted.
//!
//! The solid a surface defines is where its generalized winding number is at least ½ in magnitude.
//! Flat caps give that solid when their bound is small; when it is not, no number can be promised,
//! so by default the part fails with its own code ([`crate::diagnostic::Code::MeshNoSolid`]) instead
//! of silently taking the convex hull. The user may choose the caps anyway, or the hull, which
//! contains the solid (the winding number is 0 outside the hull of the surface): an upper bound.

/// How a mesh whose holes' caps cannot be trusted becomes a solid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum OpenMeshModel {
    /// Flat caps when their bound is below 1e-3; otherwise the part fails.
    #[default]
    Trusted,
    /// Flat caps whatever their bound (which the estimate carries).
    Caps,
    /// The convex hull of the vertices the faces use: an upper bound on the solid.
    Hull,
}

impl OpenMeshModel {
    /// The flag's value: `caps`, `hull`, or `none` for the default.
    pub fn name(self) -> &'static str {
        match self {
            OpenMeshModel::Trusted => "none",
            OpenMeshModel::Caps => "caps",
            OpenMeshModel::Hull => "hull",
        }
    }
}

/// Largest relative bound of flat caps used without asking (volume and central inertia).
pub const TRUSTED_CAPS: f64 = 1e-3;

/// Why an open mesh has no solid to trust, for [`super::MeshErrorKind::NoSolid`].
#[derive(Debug, Clone, PartialEq)]
pub struct NoSolid {
    /// What the mesh is (`open: 12 boundary edges`).
    pub what: String,
    /// The caps' relative bound, when caps could be built (infinite: unbounded).
    pub caps_bound: Option<f64>,
    /// Most of the caps' bound comes from the caps of several holes seeing each other (an open band
    /// or dish: the winding number between them can be fractional), not from the loops' flatness.
    pub holes_see_each_other: bool,
}

impl std::fmt::Display for NoSolid {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let seen = if self.holes_see_each_other {
            " (mostly because its holes see each other: between their caps the winding number can be fractional, as in an open band or dish)"
        } else {
            ""
        };
        let why = match self.caps_bound {
            Some(b) if b.is_finite() => format!(
                "flat caps over its holes leave a bound of {b:.1e} on volume and inertia{seen}, above the {TRUSTED_CAPS:.0e} they are trusted to"
            ),
            Some(_) => format!("flat caps over its holes leave volume and inertia unbounded{seen}"),
            None => "no closing of its holes encloses a volume".to_string(),
        };
        write!(
            f,
            "mesh is {}: {why}, so it defines no solid to trust; close the mesh, or choose a model for open meshes: `--open-mesh caps` (flat caps, with that bound) or `--open-mesh hull` (its convex hull, an upper bound)",
            self.what
        )
    }
}

/// Whether a surface encloses no volume however it is closed: the convex hull of the vertices its
/// faces use is flat (exactly, or within a thousand round-offs of the faces' contributions, as
/// [`super::health`] judges a solid empty). The winding number is then 0 almost everywhere: a flat
/// plate or a two-sided sheet, which contributes nothing.
pub fn encloses_nothing(vertices: &[[f64; 3]], faces: &crate::mass::Polygons) -> bool {
    let Ok((hv, ht)) = super::hull::convex_hull_of_used(vertices, faces) else {
        return true;
    };
    let volume = crate::mass::MassProperties::from_trimesh(&hv, &ht, 1.0).mass;
    let diagonal = crate::geometry::Aabb::of(hv.iter().copied()).diagonal();
    let mut area = 0.0;
    for face in faces.iter() {
        let p = vertices[face[0] as usize];
        let mut a = [0.0f64; 3];
        for k in 1..face.len().saturating_sub(1) {
            let (u, v) = (vertices[face[k] as usize], vertices[face[k + 1] as usize]);
            let (e1, e2) = (
                [u[0] - p[0], u[1] - p[1], u[2] - p[2]],
                [v[0] - p[0], v[1] - p[1], v[2] - p[2]],
            );
            a[0] += 0.5 * (e1[1] * e2[2] - e1[2] * e2[1]);
            a[1] += 0.5 * (e1[2] * e2[0] - e1[0] * e2[2]);
            a[2] += 0.5 * (e1[0] * e2[1] - e1[1] * e2[0]);
        }
        area += (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    }
    volume <= 1e3 * f64::EPSILON * area * diagonal
}
