//! glTF 2.0 scenes (`.glb`, or `.gltf` with a `.bin`), built with `gltf-json`.
//!
//! Mesh data stay in the part frame's millimetres; the root node alone
//! carries the unit scale (0.001, to metres) and the turn that lays the
//! machine out as its operator sees it (90 degrees about glTF's Y): the
//! part's axis (Z) horizontal to the right, its X (toward the tool) away
//! from the viewer, its Y up. Each body is a node with its own mesh
//! (positions, normals, indices) and material.

use super::{MeshError, Scene};
use gltf_json as json;
use json::validation::{Checked::Valid, USize64};
use std::borrow::Cow;
use std::collections::BTreeMap;
use std::io::Write;

fn io(file: &str) -> impl Fn(String) -> MeshError + '_ {
    move |message| MeshError::Io {
        file: file.to_owned(),
        message,
    }
}

/// The document and its binary buffer; `uri` names the buffer for `.gltf`.
fn build(scene: &Scene, uri: Option<String>) -> Result<(json::Root, Vec<u8>), MeshError> {
    let mut root = json::Root {
        asset: json::Asset {
            version: "2.0".into(),
            generator: Some(format!("pilgrim {}", crate::version::VERSION)),
            ..Default::default()
        },
        ..Default::default()
    };
    let size: usize = scene
        .nodes
        .iter()
        .map(|n| n.mesh.positions.len() * 24 + n.mesh.triangles.len() * 12)
        .sum::<usize>()
        + scene.motion.as_ref().map_or(0, |m| {
            m.times.len() * 4
                + m.tracks.len() * m.times.len() * (12 + 16)
                + m.spin.as_ref().map_or(0, |s| s.times.len() * (4 + 16))
        });
    let mut bin: Vec<u8> = Vec::with_capacity(size);
    let buffer = root.push(json::Buffer {
        byte_length: USize64(size as u64),
        name: None,
        uri,
        extensions: None,
        extras: Default::default(),
    });
    let mut children = Vec::new();
    for node in &scene.nodes {
        let m = &node.mesh;
        if m.triangles.is_empty() {
            return Err(MeshError::Degenerate(format!(
                "body '{}' has no triangles",
                node.name
            )));
        }
        let mut view = |bin: &mut Vec<u8>, bytes: &dyn Fn(&mut Vec<u8>), target| {
            let start = bin.len();
            bytes(bin);
            view_of(&mut root, buffer, bin, start, Some(target))
        };
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        let pos_view = view(
            &mut bin,
            &|b: &mut Vec<u8>| {
                for p in &m.positions {
                    for v in p {
                        b.extend_from_slice(&(*v as f32).to_le_bytes());
                    }
                }
            },
            json::buffer::Target::ArrayBuffer,
        );
        for p in &m.positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k] as f32);
                hi[k] = hi[k].max(p[k] as f32);
            }
        }
        let nrm_view = view(
            &mut bin,
            &|b: &mut Vec<u8>| {
                for n in &m.normals {
                    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                    for v in n {
                        b.extend_from_slice(&((*v / len) as f32).to_le_bytes());
                    }
                }
            },
            json::buffer::Target::ArrayBuffer,
        );
        let idx_view = view(
            &mut bin,
            &|b: &mut Vec<u8>| {
                for t in &m.triangles {
                    for i in t {
                        b.extend_from_slice(&i.to_le_bytes());
                    }
                }
            },
            json::buffer::Target::ElementArrayBuffer,
        );
        let bounds = |b: Option<([f32; 3], [f32; 3])>| b.map(|(lo, hi)| (lo.to_vec(), hi.to_vec()));
        let accessor = |root: &mut json::Root, view, count, kind, ty, b| {
            accessor_of(root, view, count, kind, ty, bounds(b))
        };
        use json::accessor::{ComponentType, Type};
        let pos = accessor(
            &mut root,
            pos_view,
            m.positions.len(),
            ComponentType::F32,
            Type::Vec3,
            Some((lo, hi)),
        );
        let nrm = accessor(
            &mut root,
            nrm_view,
            m.normals.len(),
            ComponentType::F32,
            Type::Vec3,
            None,
        );
        let idx = accessor(
            &mut root,
            idx_view,
            m.triangles.len() * 3,
            ComponentType::U32,
            Type::Scalar,
            None,
        );
        let material = root.push(json::Material {
            name: Some(node.name.clone()),
            pbr_metallic_roughness: json::material::PbrMetallicRoughness {
                base_color_factor: json::material::PbrBaseColorFactor(node.color),
                metallic_factor: json::material::StrengthFactor(0.2),
                roughness_factor: json::material::StrengthFactor(0.6),
                ..Default::default()
            },
            ..Default::default()
        });
        let mut attributes = BTreeMap::new();
        attributes.insert(Valid(json::mesh::Semantic::Positions), pos);
        attributes.insert(Valid(json::mesh::Semantic::Normals), nrm);
        let mesh = root.push(json::Mesh {
            name: Some(node.name.clone()),
            primitives: vec![json::mesh::Primitive {
                attributes,
                indices: Some(idx),
                material: Some(material),
                mode: Valid(json::mesh::Mode::Triangles),
                targets: None,
                extensions: None,
                extras: Default::default(),
            }],
            weights: None,
            extensions: None,
            extras: Default::default(),
        });
        let (t, q) = parts_of(&node.pose);
        let identity_turn = q.angle() == 0.0;
        children.push(root.push(json::Node {
            name: Some(node.name.clone()),
            mesh: Some(mesh),
            translation: (t.norm() > 0.0).then(|| [t.x as f32, t.y as f32, t.z as f32]),
            rotation: (!identity_turn).then(|| {
                json::scene::UnitQuaternion([q.i as f32, q.j as f32, q.k as f32, q.w as f32])
            }),
            ..Default::default()
        }));
    }
    // The bodies that turn with the part hang from one node the spin turns.
    let mut top_children = children.clone();
    let mut spin_node = None;
    if let Some(spin) = scene.motion.as_ref().and_then(|m| m.spin.as_ref()) {
        let mut members = Vec::new();
        for name in &spin.members {
            let Some(i) = scene.nodes.iter().position(|n| &n.name == name) else {
                return Err(MeshError::Degenerate(format!(
                    "the part's turn: no body '{name}' in the scene"
                )));
            };
            members.push(children[i]);
        }
        top_children.retain(|c| !members.contains(c));
        let node = root.push(json::Node {
            name: Some(SPIN_NODE.into()),
            children: Some(members),
            ..Default::default()
        });
        top_children.push(node);
        spin_node = Some(node);
    }
    if let Some(motion) = &scene.motion {
        animate(
            &mut root, &mut bin, buffer, motion, scene, &children, spin_node,
        )?;
    }
    let half = std::f32::consts::FRAC_1_SQRT_2;
    let top = root.push(json::Node {
        name: Some(
            "pilgrim part frame (mm; its axis Z to the right, X away from the viewer)".into(),
        ),
        children: Some(top_children),
        scale: Some([0.001; 3]),
        rotation: Some(json::scene::UnitQuaternion([0.0, half, 0.0, half])),
        ..Default::default()
    });
    let scene_index = root.push(json::Scene {
        name: Some("pilgrim".into()),
        nodes: vec![top],
        extensions: None,
        extras: Default::default(),
    });
    root.scene = Some(scene_index);
    Ok((root, bin))
}

/// Records the bytes `bin[start..]` as a view of `buffer`, for `target`
/// where it has one (mesh data; an animation's have none).
fn view_of(
    root: &mut json::Root,
    buffer: json::Index<json::Buffer>,
    bin: &[u8],
    start: usize,
    target: Option<json::buffer::Target>,
) -> json::Index<json::buffer::View> {
    root.push(json::buffer::View {
        buffer,
        byte_length: USize64((bin.len() - start) as u64),
        byte_offset: Some(USize64(start as u64)),
        byte_stride: None,
        name: None,
        target: target.map(Valid),
        extensions: None,
        extras: Default::default(),
    })
}

/// An accessor of `count` elements of `ty` (components of `kind`) in
/// `view`, with their least and greatest components where given.
fn accessor_of(
    root: &mut json::Root,
    view: json::Index<json::buffer::View>,
    count: usize,
    kind: json::accessor::ComponentType,
    ty: json::accessor::Type,
    bounds: Option<(Vec<f32>, Vec<f32>)>,
) -> json::Index<json::Accessor> {
    let (min, max) = bounds.map_or((None, None), |(lo, hi)| {
        (Some(json::Value::from(lo)), Some(json::Value::from(hi)))
    });
    root.push(json::Accessor {
        buffer_view: Some(view),
        byte_offset: None,
        count: USize64(count as u64),
        component_type: Valid(json::accessor::GenericComponentType(kind)),
        extensions: None,
        extras: Default::default(),
        type_: Valid(ty),
        min,
        max,
        name: None,
        normalized: false,
        sparse: None,
    })
}

/// The name of the node that turns the part's bodies about its axis.
pub const SPIN_NODE: &str = "part turn";

/// A rigid motion's translation and rotation.
fn parts_of(pose: &crate::math::Mat4) -> (nalgebra::Vector3<f64>, nalgebra::UnitQuaternion<f64>) {
    let r = pose.fixed_view::<3, 3>(0, 0).into_owned();
    let t = pose.fixed_view::<3, 1>(0, 3).into_owned();
    let q = nalgebra::UnitQuaternion::from_rotation_matrix(
        &nalgebra::Rotation3::from_matrix_unchecked(r),
    );
    (t, q)
}

/// Appends `motion` to `root` as one animation: a sampler of the key
/// times and each track's translations and rotations (each quaternion on
/// the side of the one before, so that the player turns the short way);
/// the part's turn, if any, on its own key times, turning `spin_node`.
///
/// # Failures
/// A track of a body the scene lacks, or of another length than the
/// times; times that do not increase; a spin's keys too far apart.
fn animate(
    root: &mut json::Root,
    bin: &mut Vec<u8>,
    buffer: json::Index<json::Buffer>,
    motion: &crate::mesh::scene::Motion,
    scene: &Scene,
    nodes: &[json::Index<json::Node>],
    spin_node: Option<json::Index<json::Node>>,
) -> Result<(), MeshError> {
    use json::accessor::{ComponentType, Type};
    let bad = |m: String| MeshError::Degenerate(format!("animation '{}': {m}", motion.name));
    if motion.times.is_empty() || motion.times.windows(2).any(|w| w[1] <= w[0]) {
        return Err(bad("its key times must be given and increase".into()));
    }
    let mut push = |root: &mut json::Root, values: &[f32], ty: Type, bounds: bool| {
        let start = bin.len();
        for v in values {
            bin.extend_from_slice(&v.to_le_bytes());
        }
        let view = view_of(root, buffer, bin, start, None);
        let per = match ty {
            Type::Scalar => 1,
            Type::Vec3 => 3,
            _ => 4,
        };
        let range = (vec![values[0]], vec![values[values.len() - 1]]);
        accessor_of(
            root,
            view,
            values.len() / per,
            ComponentType::F32,
            ty,
            bounds.then_some(range),
        )
    };
    let input = push(root, &motion.times, Type::Scalar, true);
    let (mut samplers, mut channels) = (Vec::new(), Vec::new());
    let mut channel = |samplers: &mut Vec<json::animation::Sampler>, input, output, node, path| {
        channels.push(json::animation::Channel {
            sampler: json::Index::new(samplers.len() as u32),
            target: json::animation::Target {
                node,
                path: Valid(path),
                extensions: None,
                extras: Default::default(),
            },
            extensions: None,
            extras: Default::default(),
        });
        samplers.push(json::animation::Sampler {
            input,
            interpolation: Valid(json::animation::Interpolation::Linear),
            output,
            extensions: None,
            extras: Default::default(),
        });
    };
    for (name, poses) in &motion.tracks {
        let Some(i) = scene.nodes.iter().position(|n| &n.name == name) else {
            return Err(bad(format!("no body '{name}' in the scene")));
        };
        if poses.len() != motion.times.len() {
            return Err(bad(format!(
                "body '{name}' has {} poses for {} key times",
                poses.len(),
                motion.times.len()
            )));
        }
        let (mut shifts, mut turns) = (Vec::new(), Vec::new());
        let mut last: Option<nalgebra::UnitQuaternion<f64>> = None;
        for pose in poses {
            let (t, mut q) = parts_of(pose);
            if last.is_some_and(|l| l.coords.dot(&q.coords) < 0.0) {
                q = nalgebra::UnitQuaternion::new_unchecked(-q.into_inner());
            }
            last = Some(q);
            shifts.extend([t.x as f32, t.y as f32, t.z as f32]);
            turns.extend([q.i as f32, q.j as f32, q.k as f32, q.w as f32]);
        }
        for (values, ty, path) in [
            (shifts, Type::Vec3, json::animation::Property::Translation),
            (turns, Type::Vec4, json::animation::Property::Rotation),
        ] {
            let output = push(root, &values, ty, false);
            channel(&mut samplers, input, output, nodes[i], path);
        }
    }
    if let (Some(spin), Some(node)) = (&motion.spin, spin_node) {
        let n = spin.times.len();
        if n == 0 || spin.angles.len() != n || spin.times.windows(2).any(|w| w[1] <= w[0]) {
            return Err(bad(
                "the part's turn needs increasing key times, an angle each".into(),
            ));
        }
        if let Some(k) = spin
            .angles
            .windows(2)
            .position(|w| !((w[1] - w[0]).abs() <= crate::mesh::MAX_SPIN_STEP))
        {
            return Err(bad(format!(
                "the part's turn goes {:.1} deg between its keys {} and {}, more than a player can show",
                (spin.angles[k + 1] - spin.angles[k]).to_degrees(),
                k + 1,
                k + 2
            )));
        }
        let input = push(root, &spin.times, Type::Scalar, true);
        let turns: Vec<f32> = spin
            .angles
            .iter()
            .flat_map(|a| {
                let (s, c) = (0.5 * a).sin_cos();
                [0.0, 0.0, s as f32, c as f32]
            })
            .collect();
        // Consecutive angles within a third of a turn keep each quaternion
        // on the side of the one before (their dot product is cos of half
        // the step).
        let output = push(root, &turns, Type::Vec4, false);
        channel(
            &mut samplers,
            input,
            output,
            node,
            json::animation::Property::Rotation,
        );
    }
    root.push(json::Animation {
        name: Some(motion.name.clone()),
        channels,
        samplers,
        extensions: None,
        extras: Default::default(),
    });
    Ok(())
}

/// Writes the scene as one binary glTF (`.glb`).
///
/// # Failures
/// A body without triangles; a write error.
pub fn write_glb<W: Write>(scene: &Scene, out: &mut W) -> Result<(), MeshError> {
    let err = io("scene.glb");
    let (root, bin) = build(scene, None)?;
    let text = json::serialize::to_vec(&root).map_err(|e| err(e.to_string()))?;
    let glb = gltf::binary::Glb {
        header: gltf::binary::Header {
            magic: *b"glTF",
            version: 2,
            length: 0, // to_writer computes it
        },
        json: Cow::Owned(text),
        bin: Some(Cow::Borrowed(&bin)),
    };
    glb.to_writer(out).map_err(|e| err(e.to_string()))
}

/// Writes the scene as `.gltf` JSON (to `json_out`) and its buffer (to
/// `bin_out`), the JSON naming the buffer `bin_name`.
///
/// # Failures
/// A body without triangles; a write error.
pub fn write_gltf<J: Write, B: Write>(
    scene: &Scene,
    bin_name: &str,
    json_out: &mut J,
    bin_out: &mut B,
) -> Result<(), MeshError> {
    let err = io(bin_name);
    let (root, bin) = build(scene, Some(bin_name.to_owned()))?;
    let text = json::serialize::to_string_pretty(&root).map_err(|e| err(e.to_string()))?;
    json_out
        .write_all(text.as_bytes())
        .map_err(|e| err(e.to_string()))?;
    bin_out.write_all(&bin).map_err(|e| err(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::machine::Solid;
    use crate::math::{Mat4, Vec3};
    use crate::mesh::Motion;

    /// A box that slides 10 mm along X and turns a quarter about Z at each
    /// key reads back, through the gltf crate's reader, as the keys it was
    /// given: times, translations, and rotations each on the side of the
    /// one before (the turn from 180 to 270 degrees the short way).
    #[test]
    fn a_scenes_motion_reads_back_key_by_key() {
        let mesh = crate::mesh::body_mesh(
            &Solid::Block {
                size: [10.0, 20.0, 30.0],
            },
            0.01,
        )
        .unwrap();
        let mut scene = Scene::new();
        scene.add("box", mesh, Mat4::identity(), [1.0; 4]);
        let pose = |k: usize| {
            Mat4::new_translation(&Vec3::new(10.0 * k as f64, 0.0, 0.0))
                * Mat4::from_axis_angle(&Vec3::z_axis(), std::f64::consts::FRAC_PI_2 * k as f64)
        };
        scene.motion = Some(Motion {
            name: "slide".into(),
            times: vec![0.0, 0.5, 1.0, 2.0],
            keys: vec![0, 1, 2, 3],
            tracks: vec![("box".into(), (0..4).map(pose).collect())],
            spin: None,
        });
        let mut glb = Vec::new();
        write_glb(&scene, &mut glb).unwrap();
        let doc = gltf::Gltf::from_slice(&glb).unwrap();
        let blob = doc.blob.clone().unwrap();
        let animation = doc.animations().next().unwrap();
        assert_eq!(animation.name(), Some("slide"));
        let mut seen = 0;
        for channel in animation.channels() {
            let reader = channel.reader(|_| Some(&blob[..]));
            let times: Vec<f32> = reader.read_inputs().unwrap().collect();
            assert_eq!(times, vec![0.0, 0.5, 1.0, 2.0]);
            match reader.read_outputs().unwrap() {
                gltf::animation::util::ReadOutputs::Translations(t) => {
                    let xs: Vec<f32> = t.map(|v| v[0]).collect();
                    assert_eq!(xs, vec![0.0, 10.0, 20.0, 30.0]);
                    seen += 1;
                }
                gltf::animation::util::ReadOutputs::Rotations(r) => {
                    let q: Vec<[f32; 4]> = r.into_f32().collect();
                    for (k, w) in q.windows(2).enumerate() {
                        let dot: f32 = (0..4).map(|i| w[0][i] * w[1][i]).sum();
                        assert!(
                            (dot - std::f32::consts::FRAC_1_SQRT_2).abs() < 1e-6,
                            "{k}: {q:?}"
                        );
                    }
                    // A quarter turn about +Z at the second key.
                    let h = std::f32::consts::FRAC_1_SQRT_2;
                    assert!((q[1][2] - h).abs() < 1e-6 && (q[1][3] - h).abs() < 1e-6);
                    seen += 1;
                }
                _ => panic!("a channel of another kind"),
            }
        }
        assert_eq!(seen, 2);
        // Times that do not increase are refused.
        scene.motion.as_mut().unwrap().times = vec![0.0, 0.5, 0.5, 2.0];
        assert!(write_glb(&scene, &mut Vec::new()).is_err());
    }

    /// A spin hangs its members from one node it turns about Z, on its own
    /// key times; a step a player would show turning back is refused.
    #[test]
    fn a_spin_turns_its_members_on_its_own_keys() {
        let mesh = crate::mesh::body_mesh(&Solid::Block { size: [1.0; 3] }, 0.01).unwrap();
        let mut scene = Scene::new();
        scene.add("box", mesh.clone(), Mat4::identity(), [1.0; 4]);
        scene.add("tool", mesh, Mat4::identity(), [1.0; 4]);
        let spin = |angles: Vec<f64>| crate::mesh::Spin {
            members: vec!["box".into()],
            times: (0..angles.len()).map(|k| k as f32 * 0.25).collect(),
            angles,
        };
        scene.motion = Some(Motion {
            name: "turn".into(),
            times: vec![0.0, 1.0],
            keys: vec![0, 1],
            tracks: vec![("tool".into(), vec![Mat4::identity(); 2])],
            spin: Some(spin(vec![0.0, 2.0, 4.0, 6.0, 8.0])),
        });
        let mut glb = Vec::new();
        write_glb(&scene, &mut glb).unwrap();
        let doc = gltf::Gltf::from_slice(&glb).unwrap();
        let blob = doc.blob.clone().unwrap();
        let turn = doc.nodes().find(|n| n.name() == Some(SPIN_NODE)).unwrap();
        let members: Vec<_> = turn
            .children()
            .map(|c| c.name().unwrap().to_owned())
            .collect();
        assert_eq!(members, vec!["box".to_owned()]);
        let channel = doc
            .animations()
            .next()
            .unwrap()
            .channels()
            .find(|c| c.target().node().index() == turn.index())
            .unwrap();
        let reader = channel.reader(|_| Some(&blob[..]));
        assert_eq!(reader.read_inputs().unwrap().count(), 5);
        let gltf::animation::util::ReadOutputs::Rotations(r) = reader.read_outputs().unwrap()
        else {
            panic!("the turn is a rotation");
        };
        for (k, q) in r.into_f32().enumerate() {
            let a = 2.0 * k as f64;
            assert!((q[2] as f64 - (a / 2.0).sin()).abs() < 1e-6);
            assert!((q[3] as f64 - (a / 2.0).cos()).abs() < 1e-6);
        }
        scene.motion.as_mut().unwrap().spin = Some(spin(vec![0.0, 2.2]));
        let e = write_glb(&scene, &mut Vec::new()).unwrap_err();
        assert!(e.to_string().contains("126.1 deg"), "{e}");
    }
}
