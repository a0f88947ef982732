//! Attribute values: the attributes of a tag, numbers, vectors, poses and geometry shapes, each with a
//! message saying what is wrong.

use super::describe;
use super::model::{Geometry, Pose};
use crate::mass::primitives;
use quick_xml::events::attributes::AttrError;
use quick_xml::events::BytesStart;
use std::collections::HashMap;

/// The attributes of a start tag. A duplicate or malformed attribute is malformed XML (urdfdom's
/// `TinyXML` refuses the file): its offset in the tag (after `<`) and the message.
pub(super) fn attrs(e: &BytesStart<'_>) -> Result<HashMap<String, String>, (usize, String)> {
    let mut m = HashMap::new();
    for a in e.attributes().with_checks(true) {
        let a = a.map_err(|err| match err {
            AttrError::Duplicated(at, _) => {
                let key: String = String::from_utf8_lossy(e.get(at..).unwrap_or_default())
                    .chars()
                    .take_while(|c| *c != '=' && !c.is_whitespace())
                    .collect();
                (at, format!("attribute `{key}` is given twice in <{}>; an attribute may appear once (which value is meant?)", String::from_utf8_lossy(e.name().as_ref())))
            }
            AttrError::ExpectedEq(at)
            | AttrError::ExpectedValue(at)
            | AttrError::UnquotedValue(at)
            | AttrError::ExpectedQuote(at, _) => (at, format!("malformed attribute: {err}")),
        })?;
        let key = String::from_utf8_lossy(a.key.as_ref()).into_owned();
        let v = a.unescape_value().map_or_else(
            |_| String::from_utf8_lossy(&a.value).into_owned(),
            std::borrow::Cow::into_owned,
        );
        m.insert(key, v);
    }
    Ok(m)
}

pub(super) fn parse_vec3(s: &str) -> Result<[f64; 3], String> {
    let v: Vec<&str> = s.split_ascii_whitespace().collect();
    if v.len() != 3 {
        return Err(format!(
            "\"{s}\" should be three numbers, not {} (urdfdom logs an error and drops this link's collision geometry)",
            v.len()
        ));
    }
    let mut out = [0.0; 3];
    for (o, w) in out.iter_mut().zip(v) {
        *o = w
            .parse::<f64>()
            .map_err(|_| format!("\"{w}\" in \"{s}\" is not a number"))?;
        if !o.is_finite() {
            return Err(format!("\"{s}\" is not finite"));
        }
    }
    Ok(out)
}

pub(super) fn pose(a: &HashMap<String, String>) -> Result<Pose, String> {
    Ok(Pose {
        xyz: a
            .get("xyz")
            .map(|s| parse_vec3(s).map_err(|m| format!("xyz {m}")))
            .transpose()?
            .unwrap_or([0.0; 3]),
        rpy: a
            .get("rpy")
            .map(|s| parse_vec3(s).map_err(|m| format!("rpy {m}")))
            .transpose()?
            .unwrap_or([0.0; 3]),
    })
}

pub(super) fn num(a: &HashMap<String, String>, key: &str) -> Result<f64, String> {
    let s = a
        .get(key)
        .ok_or_else(|| format!("missing attribute `{key}`"))?;
    s.trim().parse::<f64>().map_err(|_| {
        format!(
            "{key}=\"{}\" is not a number",
            crate::text::escape_control(s)
        )
    })
}

/// A primitive's size: finite and not negative (zero is valid URDF).
pub(super) fn size(a: &HashMap<String, String>, key: &str) -> Result<f64, String> {
    let v = num(a, key)?;
    if !v.is_finite() {
        Err(format!("{key}=\"{v}\" is not a finite number"))
    } else if v < 0.0 {
        Err(format!("{key}=\"{v}\" must not be negative"))
    } else {
        Ok(v)
    }
}

pub(super) fn geometry(kind: &str, a: &HashMap<String, String>) -> Result<Geometry, String> {
    let g = match kind {
        "mesh" => {
            let filename = a
                .get("filename")
                .cloned()
                .ok_or("<mesh> without filename")?;
            let scale = match a.get("scale") {
                None => [1.0; 3],
                Some(s) => {
                    let v: Vec<&str> = s.split_ascii_whitespace().collect();
                    // urdfdom accepts one number for a uniform scale as well as three.
                    if v.len() == 1 {
                        let x: f64 = v[0]
                            .parse()
                            .map_err(|_| format!("scale \"{s}\" is not a number"))?;
                        if !x.is_finite() {
                            return Err(format!("scale \"{s}\" is not finite"));
                        }
                        [x; 3]
                    } else {
                        parse_vec3(s).map_err(|m| format!("mesh scale {m}"))?
                    }
                }
            };
            if scale.contains(&0.0) {
                return Err(format!(
                    "mesh scale \"{} {} {}\" has a zero factor",
                    scale[0], scale[1], scale[2]
                ));
            }
            return Ok(Geometry::Mesh { filename, scale });
        }
        "box" => {
            let size = parse_vec3(a.get("size").ok_or("<box> without size")?)
                .map_err(|m| format!("box size {m}"))?;
            if size.iter().any(|x| *x < 0.0) {
                return Err(format!(
                    "box size \"{} {} {}\" must not be negative",
                    size[0], size[1], size[2]
                ));
            }
            Geometry::Box { size }
        }
        "cylinder" => Geometry::Cylinder {
            radius: size(a, "radius")?,
            length: size(a, "length")?,
        },
        "capsule" => Geometry::Capsule {
            radius: size(a, "radius")?,
            length: size(a, "length")?,
        },
        "sphere" => Geometry::Sphere {
            radius: size(a, "radius")?,
        },
        other => {
            return Err(format!(
                "unknown geometry <{other}> (urdfdom logs an error and drops this link's collision geometry); give this collision a <box>, <cylinder>, <sphere>, <capsule> or <mesh>"
            ))
        }
    };
    // A finite size can still overflow the volume or inertia (a box of 1e120 m): refuse it here.
    let unit = match &g {
        Geometry::Box { size } => primitives::cuboid(*size, 1.0),
        Geometry::Cylinder { radius, length } => primitives::cylinder(*radius, *length, 1.0),
        Geometry::Capsule { radius, length } => primitives::capsule(*radius, *length, 1.0),
        Geometry::Sphere { radius } => primitives::sphere(*radius, 1.0),
        Geometry::Mesh { .. } | Geometry::Invalid { .. } => return Ok(g),
    };
    if unit.mass.is_finite() && unit.inertia.iter().flatten().all(|x| x.is_finite()) {
        Ok(g)
    } else {
        Err(format!(
            "{} is too large: its volume or inertia overflows a 64-bit float (check the units: metres)",
            describe(&g)
        ))
    }
}
