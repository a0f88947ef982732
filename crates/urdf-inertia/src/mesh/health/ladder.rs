//! What every rung shares: where the mesh came from, what has been said about it, the overlapping
//! shells' classification and the last step (integrate, check the volume, estimate the error).

use super::geometry::{bbox, unit_props};
use super::model::{check_volume, reach, round_off, Lever, Model};
use super::{ErrorEstimate, HealthKind, HealthMessage, HealthOptions, ModelError, Rung, Solid};
use crate::geometry::dot;
use crate::mass::integrals::VolumeIntegrals;
use crate::mass::{MassProperties, Polygons};
use crate::mesh::{winding_shells, MeshError, MeshErrorKind, RawMesh};
use std::path::Path;

/// Shared by the rungs: where the mesh came from and what has been said about it.
#[derive(Clone)]
pub(super) struct Ladder<'a> {
    pub(super) path: &'a Path,
    pub(super) options: HealthOptions,
    pub(super) warnings: Vec<HealthMessage>,
    pub(super) notes: Vec<HealthMessage>,
    pub(super) faces_read: usize,
    /// The integrals of the faces `finish` gets, when a rung already has them (a clean mesh is then
    /// integrated twice, not three times: once here, once about a second reference point).
    pub(super) known: Option<VolumeIntegrals>,
    /// The faces as stored, where welding and the rungs changed them (whose winding number defines
    /// the solid where shells overlap).
    pub(super) as_stored: winding_shells::AsStored,
    /// A closed surface of several components whose boxes overlap: its shells are classified like
    /// the repaired rungs' (a region two of them enclose counts once).
    pub(super) overlapping_components: bool,
}

impl<'a> Ladder<'a> {
    /// A ladder starting with what the reader said about `mesh`.
    pub(super) fn new(mesh: &RawMesh, path: &'a Path, options: HealthOptions) -> Self {
        Ladder {
            path,
            options,
            warnings: mesh
                .warnings
                .iter()
                .map(|w| HealthMessage::new(HealthKind::ReaderSkipped, w.clone()))
                .collect(),
            notes: mesh
                .notes
                .iter()
                .map(|n| HealthMessage::new(HealthKind::ReaderNote, n.clone()))
                .collect(),
            faces_read: mesh.faces.len(),
            known: None,
            as_stored: winding_shells::AsStored::default(),
            overlapping_components: false,
        }
    }

    pub(super) fn warn(&mut self, kind: HealthKind, text: String) {
        self.warnings.push(HealthMessage::new(kind, text));
    }

    pub(super) fn note(&mut self, kind: HealthKind, text: String) {
        self.notes.push(HealthMessage::new(kind, text));
    }

    pub(super) fn strict(&self, what: &str) -> Result<(), MeshError> {
        if self.options.strict {
            Err(MeshError::new(
                self.path,
                None,
                MeshErrorKind::Strict(what.to_string()),
            ))
        } else {
            Ok(())
        }
    }

    /// On the repaired rungs, the faces that bound the solid when shells overlap (see
    /// [`super::winding_shells`]): doubly enclosed shells dropped, inside-out ones turned, and what is
    /// left undecided bounded in `model`. The surfaces integrated as stored pay nothing.
    pub(super) fn shells(
        &mut self,
        vertices: &mut Vec<[f64; 3]>,
        faces: Polygons,
        rung: &Rung,
        model: &mut Model,
    ) -> Polygons {
        if !self.overlapping_components
            && !matches!(
                rung,
                Rung::Capped { .. } | Rung::NonManifold { .. } | Rung::Reoriented { .. }
            )
        {
            return faces;
        }
        let mut s = winding_shells::classify(vertices, &faces, &self.as_stored);
        if s.whole_as_stored {
            // The file's surface, every face decided by its winding number: what the rung assumed
            // about closure and orientation no longer enters the solid.
            model.terms.clear();
        }
        if s.resolved_pairs > 0 {
            self.resolved(&s, model);
        }
        if s.overlap_bound > 0.0 {
            let others: f64 = model.terms.iter().map(|t| t.0).sum();
            if s.overlap_bound > others {
                model.source = ModelError::Overlap;
            }
            model.terms.push((s.overlap_bound, Lever::Anywhere));
            // Shells closed up to cracks add the volume their cracks leave undefined; with no
            // undecided pair that is all the bound is.
            let text = if s.undecided_pairs > 0 {
                format!("{} pair(s) of shells touch or cut each other (or are open) where their boxes overlap: the volume they may count twice, at most {:.2e} m³ (their boxes' intersections), is in the error estimate",
                    s.undecided_pairs, s.overlap_bound)
            } else {
                format!("shells closed up to cracks were classified as closed: the volume their cracks leave undefined, at most {:.2e} m³, is in the error estimate",
                    s.overlap_bound)
            };
            self.warn(HealthKind::Repaired, text);
        }
        if !s.changed {
            return faces;
        }
        self.known = None;
        vertices.append(&mut s.vertices);
        let mut done = Vec::new();
        if s.dropped_shells > 0 {
            done.push(format!(
                "{} shell(s) ({} faces) inside the solid on both sides left out (an internal wall or a region enclosed twice would count twice)",
                s.dropped_shells, s.dropped_faces
            ));
        }
        if s.turned_shells > 0 {
            done.push(format!(
                "{} shell(s) turned round (inside-out, or a cavity wound outward), so each counts once",
                s.turned_shells
            ));
        }
        if !done.is_empty() {
            self.warn(
                HealthKind::Repaired,
                format!("overlapping shells: {}", done.join("; ")),
            );
        }
        s.faces
    }

    /// What deciding touching or cutting closed shells face by face left open, in `model` and in a
    /// warning.
    fn resolved(&mut self, s: &winding_shells::ShellOutcome, model: &mut Model) {
        let bound = if s.resolved_bound > 0.0 {
            let others: f64 = model.terms.iter().map(|t| t.0).sum();
            if s.resolved_bound > others {
                model.source = ModelError::Overlap;
            }
            model
                .terms
                .push((s.resolved_bound, Lever::Ball(s.ball.0, s.ball.1)));
            format!(
                "; the pieces along the cuts left undecided may change at most {:.2e} m³, which is in the error estimate",
                s.resolved_bound
            )
        } else {
            String::new()
        };
        let mut stored = Vec::new();
        if s.copies_restored > 0 {
            stored.push(format!("{} face copies put back", s.copies_restored));
            // Welding said the copies were dropped; where shells are decided, they are not.
            if let Some(w) = self
                .warnings
                .iter_mut()
                .find(|w| w.kind == HealthKind::FacesDropped && w.text.contains("more than once"))
            {
                let put_back = format!(
                    "; {} of the copies put back where overlapping shells are decided by the winding number of the surface as stored, which counts each copy",
                    s.copies_restored
                );
                w.text += &put_back;
            }
        }
        if s.turned_back > 0 {
            stored.push(format!("{} re-oriented faces as stored", s.turned_back));
        }
        if s.cracks_welded {
            stored.push("cracks welded".to_string());
        }
        let stored = if stored.is_empty() {
            String::new()
        } else {
            format!(", on the surface as stored: {}", stored.join(", "))
        };
        self.warn(HealthKind::Repaired, format!(
            "{} pair(s) of closed shells touch or cut each other: their faces are decided piece by piece by the winding number on each side ({} triangle(s) cut by others and split{stored}){bound}",
            s.resolved_pairs, s.cut_faces
        ));
    }

    /// Integrates, checks the volume and estimates the error: the last step of every rung. `model`
    /// is the volume (m³) by which the solid can differ from the stored surface, and what it is made
    /// of; `message` turns the relative model error into the rung's warning, if it has one.
    pub(super) fn finish(
        mut self,
        vertices: Vec<[f64; 3]>,
        faces: Polygons,
        rung: Rung,
        model: impl Into<Model>,
        message: impl FnOnce(f64, f64) -> Option<String>,
    ) -> Result<Solid, MeshError> {
        let mut model = model.into();
        let mut vertices = vertices;
        let faces = self.shells(&mut vertices, faces, &rung, &mut model);
        let unit = match self.known.take() {
            Some(t) => MassProperties::from_integrals(&t, 1.0),
            None => unit_props(&vertices, &faces, None),
        };
        // One pass for the box both checks use.
        let bounds = bbox(&vertices);
        check_volume(&vertices, &faces, bounds, unit.mass, self.path)?;
        let round_off = round_off(&vertices, &faces, bounds.lo, &unit);
        let source = model.source;
        let bound = model.bound(&unit, &vertices);
        let model_error = bound.relative;
        if let Some(m) = message(model_error, unit.mass) {
            self.warn(HealthKind::Repaired, m);
        }
        let mut rung = rung;
        if let Rung::Capped {
            relative_uncertainty,
            ..
        } = &mut rung
        {
            *relative_uncertainty = model_error;
        }
        // Round-off shifts the centre by the relative round-off of the first moments, about the
        // reference point.
        let com =
            bound.com + round_off * (reach(&unit, &vertices) + dot(unit.com, unit.com).sqrt());
        let error = ErrorEstimate {
            round_off,
            model: model_error,
            com,
            source: if model_error > 0.0 {
                source
            } else {
                ModelError::None
            },
        };
        Ok(Solid {
            vertices,
            faces,
            rung,
            warnings: self.warnings,
            notes: self.notes,
            unit,
            error_estimate: error.total(),
            error,
            faces_read: self.faces_read,
        })
    }
}
