//! COLLADA (.dae), read with quick-xml.
//!
//! Convention (what ROS tools and pinocchio do with robot meshes):
//! * every `<instance_geometry>` reachable from the scene's `<instance_visual_scene>` counts, each moved
//!   by the product of its ancestors' node transforms (`<matrix>`, `<translate>`, `<rotate>`, `<scale>`,
//!   in document order; `<instance_node>` follows `<library_nodes>`); without a scene, every geometry
//!   counts once, untransformed;
//! * `<unit meter="s">` scales all coordinates by `s` (as `RViz` and Gazebo do);
//! * `<up_axis>` is **not** applied: coordinates are taken as authored in the URDF link frame, which is
//!   what `RViz`, Gazebo and pinocchio (coal's assimp loader) show for `Y_UP` files; the mesh validation
//!   on example-robot-data compares this against coal.
//! * `<triangles>`, `<polylist>` and `<polygons>` are read (polygons stay polygons; holes in `<ph>` are
//!   not supported and reported); `<lines>` and `<linestrips>` carry no surface and are skipped.

use super::affine::IDENTITY;
use super::{MeshError, MeshErrorKind, RawMesh};
use crate::mass::Polygons;
use std::collections::HashMap;
use std::path::Path;

mod geometry;
mod scene;
mod tree;

use scene::{add_scene, Instancer};
use tree::{parse_tree, El};

/// A syntax error at `line`.
fn syntax_at(path: &Path, line: usize, msg: String) -> MeshError {
    MeshError::new(path, Some(line), MeshErrorKind::Syntax(msg))
}

/// Parses a COLLADA document into one mesh in the file's frame (see the module docs for the convention).
pub fn parse(bytes: &[u8], path: &Path) -> Result<RawMesh, MeshError> {
    let (doc, tail) = parse_tree(bytes, path)?;
    let root = doc
        .children
        .iter()
        .find(|c| c.name == "COLLADA")
        .ok_or_else(|| {
            MeshError::new(
                path,
                Some(1),
                MeshErrorKind::Syntax("no <COLLADA> root element".into()),
            )
        })?;
    let unit_el = root.child("asset").and_then(|a| a.child("unit"));
    let unit = unit_of(unit_el, path)?;

    let mut all: Vec<&El> = Vec::new();
    root.walk(&mut all);
    let by_id: HashMap<&str, &El> = all
        .iter()
        .filter_map(|e| e.attr("id").map(|id| (id, *e)))
        .collect();

    let mut inst = Instancer {
        bytes,
        path,
        unit,
        geom_cache: HashMap::new(),
        corners: 0,
        unit_loss: None,
        out: RawMesh {
            faces: Polygons::new(),
            ..Default::default()
        },
        notes: Vec::new(),
    };
    if let Some(line) = tail {
        inst.notes.push(format!(
            "warning: the file goes on after its </COLLADA> end tag (line {line}): that text is not read, as assimp (RViz, Gazebo, pinocchio) does not read it; it may be the end of an older, longer file saved over, so check that the mesh is whole"
        ));
    }
    if let Some(scene) = visual_scene(root, &by_id) { add_scene(scene, &by_id, &mut inst)? } else {
        if let Some(lib) = root.child("library_geometries") {
            for g in lib.children_named("geometry") {
                inst.add(g, &IDENTITY)?;
            }
        }
        inst.notes
            .push("no visual scene: every geometry counted once, untransformed".into());
    }
    let Instancer {
        mut out,
        notes,
        unit_loss: inst_unit_loss,
        ..
    } = inst;
    let inst_unit_loss = inst_unit_loss.or_else(|| unit_extent_loss(&out.vertices, unit));
    if let (Some(what), Some(u)) = (inst_unit_loss, unit_el) {
        return Err(MeshError::new(
            path,
            Some(u.line),
            MeshErrorKind::Syntax(format!(
                "with <unit meter=\"{}\">, the mesh's coordinates, volume or inertia {what} a 64-bit float; fix the unit or the mesh's coordinates",
                crate::text::escape_control(u.attr("meter").unwrap_or_default())
            )),
        ));
    }
    // Reader messages that say something was left out are warnings; the rest are notes.
    for n in notes {
        match n.strip_prefix("warning: ") {
            Some(w) => out.warnings.push(w.to_string()),
            None => out.notes.push(n),
        }
    }
    Ok(out)
}

/// The scene's `<instance_visual_scene>`, else the first `<visual_scene>` of the library, if any.
fn visual_scene<'a>(root: &'a El, by_id: &HashMap<&str, &'a El>) -> Option<&'a El> {
    root.child("scene")
        .and_then(|s| s.child("instance_visual_scene"))
        .and_then(|i| i.attr("url"))
        .and_then(|u| by_id.get(u.trim_start_matches('#')).copied())
        .or_else(|| {
            root.child("library_visual_scenes")
                .and_then(|l| l.child("visual_scene"))
        })
}

/// Metres per unit: `<unit meter="s">`'s value, 1 without the element or the attribute. Anything but
/// a positive finite decimal (`0,001`, `1 mm`, `0`, `-1`, `inf`) is an error: read as 1 m, a millimetre
/// file would weigh 10⁹ times too much without a word.
fn unit_of(unit: Option<&El>, path: &Path) -> Result<f64, MeshError> {
    let Some((el, text)) = unit.and_then(|u| u.attr("meter").map(|m| (u, m))) else {
        return Ok(1.0);
    };
    match text.trim().parse::<f64>() {
        Ok(m) if m.is_finite() && m > 0.0 => Ok(m),
        _ => Err(MeshError::new(
            path,
            Some(el.line),
            MeshErrorKind::Syntax(format!(
                "<unit meter=\"{}\"> is not a positive number of metres (write a decimal with a point, e.g. meter=\"0.001\" for millimetres)",
                crate::text::escape_control(text)
            )),
        )),
    }
}

/// What multiplying an authored coordinate by the unit did to it, when it lost it: `<unit
/// meter="1e308">` overflows, `meter="1e-310"` underflows, and either would otherwise be reported as
/// a flat mesh of NaN or zero volume.
fn unit_range_loss(authored: f64, scaled: f64) -> Option<&'static str> {
    if authored.is_finite() && !scaled.is_finite() {
        Some("overflows")
    } else if authored.is_normal() && !scaled.is_normal() {
        Some("underflows")
    } else {
        None
    }
}

/// Whether the unit made the mesh's size overflow or underflow what its inertia (the fifth power of
/// the size) can hold, when the authored size could: `<unit meter="1e308">` on a 1-unit box.
fn unit_extent_loss(vertices: &[[f64; 3]], unit: f64) -> Option<&'static str> {
    if unit == 1.0 || vertices.is_empty() {
        return None;
    }
    let size = crate::geometry::Aabb::of(vertices.iter().copied()).largest_extent();
    let authored = size / unit;
    unit_range_loss(authored.powi(5), size.powi(5))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit tetrahedron whose `<p>` text is `p` and whose document has `extra` sources.
    fn tetra(p: &str, extra: &str) -> String {
        format!(
            "<COLLADA><library_geometries><geometry id=\"g\"><mesh>\n<source id=\"pos\"><float_array id=\"a\">0 0 0 1 0 0 0 1 0 0 0 1</float_array><technique_common><accessor source=\"#a\" stride=\"3\"/></technique_common></source>{extra}\n<triangles count=\"4\"><input semantic=\"VERTEX\" source=\"#pos\" offset=\"0\"/><p>{p}</p></triangles>\n</mesh></geometry></library_geometries></COLLADA>"
        )
    }

    const FACES: &str = "0 2 1 0 1 3 0 3 2 1 2 3";

    #[test]
    fn text_is_read_in_place_and_joined_across_comments() {
        let m = parse(tetra(FACES, "").as_bytes(), Path::new("t.dae")).unwrap();
        assert_eq!(m.vertices.len(), 4);
        assert_eq!(m.faces.indices, [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3]);
        // XML joins the text around a comment: "1<!-- -->3" is 13 (out of range), "1 <!-- -->3" two.
        let joined = tetra("0 2 1 0 1<!-- c -->3 0 3 2 1 2 3", "");
        let e = parse(joined.as_bytes(), Path::new("t.dae")).unwrap_err();
        assert!(
            matches!(e.kind, MeshErrorKind::IndexOutOfRange { index: 13, .. }),
            "{e}"
        );
        let spaced = tetra("0 2 1 0 1<!-- c --> <!-- d -->3 0 3 2 1 2 3", "");
        let m = parse(spaced.as_bytes(), Path::new("t.dae")).unwrap();
        assert_eq!(m.faces.indices, [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3]);
    }

    /// Text after the root's end tag (an older file's end left by a shorter one saved over it) is not
    /// read, with a warning at its line, as assimp reads such files; comments and whitespace there
    /// are XML and say nothing.
    #[test]
    fn the_document_ends_at_the_root_end_tag() {
        let doc = tetra(FACES, "");
        let m = parse(format!("{doc}\n<!-- c -->\n\n").as_bytes(), Path::new("t.dae")).unwrap();
        assert_eq!(m.faces.len(), 4);
        assert!(m.warnings.is_empty(), "{:?}", m.warnings);
        let tail = format!("{doc}\n\n  0 1 2 3</p>\n</triangles></mesh></geometry>\n</library_geometries></COLLADA>\n");
        let m = parse(tail.as_bytes(), Path::new("t.dae")).unwrap();
        assert_eq!(m.faces.indices, [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3]);
        let lines = doc.lines().count();
        assert_eq!(m.warnings.len(), 1, "{:?}", m.warnings);
        assert!(
            m.warnings[0].contains(&format!("goes on after its </COLLADA> end tag (line {})", lines + 2)),
            "{:?}",
            m.warnings
        );
        // A second root element is such a tail too.
        let m = parse(format!("{doc}<COLLADA></COLLADA>").as_bytes(), Path::new("t.dae")).unwrap();
        assert!(m.warnings[0].contains(&format!("(line {lines})")), "{:?}", m.warnings);
    }

    /// Sources no VERTEX input names (normals, texture coordinates) are never parsed.
    #[test]
    fn unused_sources_are_not_parsed() {
        let normals = "<source id=\"n\"><float_array id=\"na\">not numbers</float_array></source>";
        let m = parse(tetra(FACES, normals).as_bytes(), Path::new("t.dae")).unwrap();
        assert_eq!(m.faces.len(), 4);
    }

    /// A trailing incomplete triangle is ignored; a bad number anywhere in `<p>` is an error.
    #[test]
    fn triangles_stream_their_indices() {
        let m = parse(
            tetra(&format!("{FACES} 0 1"), "").as_bytes(),
            Path::new("t.dae"),
        )
        .unwrap();
        assert_eq!(m.faces.len(), 4);
        let e = parse(
            tetra(&format!("{FACES} x"), "").as_bytes(),
            Path::new("t.dae"),
        )
        .unwrap_err();
        assert!(e.to_string().contains("`x` is not a number in <p>"), "{e}");
    }

    /// The indices of other inputs (here a normal's) are passed over unconverted, but still have to be
    /// numbers: any spelling of one is taken, anything else is the same error as in a vertex slot.
    #[test]
    fn other_inputs_indices_are_passed_over_but_checked() {
        let with_normals = |normal: &str| {
            let p: Vec<String> = FACES.split(' ').map(|v| format!("{v} {normal}")).collect();
            format!(
                "<COLLADA><library_geometries><geometry id=\"g\"><mesh>\n<source id=\"pos\"><float_array id=\"a\">0 0 0 1 0 0 0 1 0 0 0 1</float_array><technique_common><accessor source=\"#a\" stride=\"3\"/></technique_common></source>\n<triangles count=\"4\"><input semantic=\"VERTEX\" source=\"#pos\" offset=\"0\"/><input semantic=\"NORMAL\" source=\"#n\" offset=\"1\"/><p>{}</p></triangles>\n</mesh></geometry></library_geometries></COLLADA>",
                p.join("\n")
            )
        };
        for normal in [
            "7",
            "0",
            "123456789012345678901234",
            "1.0",
            "+2",
            "3e0",
            "-1",
            ".5",
        ] {
            let m = parse(with_normals(normal).as_bytes(), Path::new("t.dae")).unwrap();
            assert_eq!(
                m.faces.indices,
                [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3],
                "{normal}"
            );
        }
        for bad in ["x", "1x", "7,"] {
            let e = parse(with_normals(bad).as_bytes(), Path::new("t.dae")).unwrap_err();
            assert!(
                e.to_string()
                    .contains(&format!("`{bad}` is not a number in <p>")),
                "{e}"
            );
        }
    }
}
