//! The mannequin's skeleton: bones with rest head and tail positions and a parent, read from a
//! MakeHuman `.mhskel` file.
//!
//! A `.mhskel` file is JSON: `bones` maps a bone name to its `head` and `tail` joint names and
//! its `parent` (`null` for the root); `joints` maps a joint name to a list of 0-based vertex
//! indices of the base mesh, whose mean is the joint position. Bones are stored parents first
//! (a topological order, siblings by name), so one pass over them composes transforms down
//! the hierarchy.

use std::collections::{BTreeMap, HashMap};

use serde::Deserialize;

use super::error::BodyError;
use crate::geometry::Vec3;

/// One bone of the skeleton, at rest.
#[derive(Clone, Debug)]
pub struct Bone {
    /// Bone name (`upperleg01.L`, `spine03`, ...).
    pub name: String,
    /// Index of the parent bone (always smaller than this bone's); `None` for the root.
    pub parent: Option<usize>,
    /// Name of the joint at the bone's head.
    pub head_joint: String,
    /// Name of the joint at the bone's tail.
    pub tail_joint: String,
    /// Rest position of the head (world, metres, z up).
    pub head: Vec3,
    /// Rest position of the tail (world, metres, z up).
    pub tail: Vec3,
}

/// A joint: the base-mesh vertices whose mean is its position.
#[derive(Clone, Debug)]
pub struct Joint {
    /// Joint name.
    pub name: String,
    /// 0-based indices into the full base mesh (helper vertices included).
    pub vertices: Vec<usize>,
    /// Rest position (world, metres, z up).
    pub rest: Vec3,
}

/// Bones (parents first) and the joints they are built from.
#[derive(Clone, Debug)]
pub struct Skeleton {
    bones: Vec<Bone>,
    joints: Vec<Joint>,
    bone_index: HashMap<String, usize>,
    joint_index: HashMap<String, usize>,
}

#[derive(Deserialize)]
struct SkelFile {
    bones: BTreeMap<String, BoneDef>,
    joints: BTreeMap<String, Vec<usize>>,
}

#[derive(Deserialize)]
struct BoneDef {
    head: String,
    tail: String,
    parent: Option<String>,
}

impl Skeleton {
    /// Parses `.mhskel` JSON; `positions` are the full base-mesh vertices, already in world
    /// coordinates, that joint indices refer to. `file` names the text in errors.
    pub fn parse_mhskel(text: &str, file: &str, positions: &[Vec3]) -> Result<Skeleton, BodyError> {
        let def: SkelFile = serde_json::from_str(text).map_err(|e| BodyError::json(file, &e))?;
        let mut joints = Vec::with_capacity(def.joints.len());
        let mut joint_index = HashMap::new();
        for (name, vertices) in def.joints {
            if vertices.is_empty() {
                return Err(BodyError::invalid(
                    file,
                    format!("joint '{name}' has no vertex"),
                ));
            }
            let mut sum = Vec3::zeros();
            for &v in &vertices {
                let p = positions.get(v).ok_or_else(|| {
                    BodyError::invalid(
                        file,
                        format!(
                            "joint '{name}' refers to vertex {v}, but the mesh has {}",
                            positions.len()
                        ),
                    )
                })?;
                sum += p;
            }
            let rest = sum / vertices.len() as f64;
            joint_index.insert(name.clone(), joints.len());
            joints.push(Joint {
                name,
                vertices,
                rest,
            });
        }
        // topological order: roots first, then children of already placed bones, by name
        let mut children: BTreeMap<Option<&str>, Vec<&str>> = BTreeMap::new();
        for (name, b) in &def.bones {
            if let Some(p) = &b.parent {
                if !def.bones.contains_key(p) {
                    return Err(BodyError::invalid(
                        file,
                        format!("bone '{name}' has an unknown parent '{p}'"),
                    ));
                }
            }
            children
                .entry(b.parent.as_deref())
                .or_default()
                .push(name.as_str());
        }
        let mut order: Vec<&str> = children.get(&None).cloned().unwrap_or_default();
        let mut i = 0;
        while i < order.len() {
            if let Some(c) = children.get(&Some(order[i])) {
                order.extend(c.iter().copied());
            }
            i += 1;
        }
        if order.len() != def.bones.len() || order.is_empty() {
            return Err(BodyError::invalid(
                file,
                "the bone hierarchy has no root or contains a cycle",
            ));
        }
        let mut bones = Vec::with_capacity(order.len());
        let mut bone_index = HashMap::new();
        for name in order {
            let b = &def.bones[name];
            let joint = |j: &str| {
                joint_index.get(j).map(|&k| joints[k].rest).ok_or_else(|| {
                    BodyError::invalid(file, format!("bone '{name}' refers to unknown joint '{j}'"))
                })
            };
            let head = joint(&b.head)?;
            let tail = joint(&b.tail)?;
            let parent = b.parent.as_ref().map(|p| bone_index[p.as_str()]);
            bone_index.insert(name.to_string(), bones.len());
            bones.push(Bone {
                name: name.to_string(),
                parent,
                head_joint: b.head.clone(),
                tail_joint: b.tail.clone(),
                head,
                tail,
            });
        }
        Ok(Skeleton {
            bones,
            joints,
            bone_index,
            joint_index,
        })
    }

    /// All bones, parents before children.
    pub fn bones(&self) -> &[Bone] {
        &self.bones
    }

    /// Number of bones.
    pub fn len(&self) -> usize {
        self.bones.len()
    }

    /// Whether the skeleton has no bone (never true for a loaded one).
    pub fn is_empty(&self) -> bool {
        self.bones.is_empty()
    }

    /// Index of the bone called `name`.
    pub fn bone_index(&self, name: &str) -> Option<usize> {
        self.bone_index.get(name).copied()
    }

    /// All joints (by name order).
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }

    /// The joint called `name`.
    pub fn joint(&self, name: &str) -> Option<&Joint> {
        self.joint_index.get(name).map(|&k| &self.joints[k])
    }

    /// Moves every bone end and joint by `f` (a grading's scale).
    pub(crate) fn map_points(&mut self, f: impl Fn(Vec3) -> Vec3) {
        for b in &mut self.bones {
            b.head = f(b.head);
            b.tail = f(b.tail);
        }
        for j in &mut self.joints {
            j.rest = f(j.rest);
        }
    }

    /// Moves every rest position by `delta` (used to put the feet on the floor).
    pub(crate) fn translate(&mut self, delta: Vec3) {
        for b in &mut self.bones {
            b.head += delta;
            b.tail += delta;
        }
        for j in &mut self.joints {
            j.rest += delta;
        }
    }
}
