//! A small SPIR-V reflector: descriptor bindings, push-constant block layout and
//! specialisation constants, all by name. Binding numbers and struct layouts are written
//! once, in GLSL; Rust binds by the variable names the shaders declare, and tests compare
//! the `#[repr(C)]` mirrors with the offsets read here.

use ash::vk;
use std::collections::HashMap;

/// One descriptor a shader declares.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BindingInfo {
    pub name: String,
    pub set: u32,
    pub binding: u32,
    pub ty: vk::DescriptorType,
    /// For storage images: the declared format (`Unknown` when absent).
    pub image_dim: Option<u32>,
}

/// A struct member: name and byte offset.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MemberInfo {
    pub name: String,
    pub offset: u32,
    pub size: u32,
}

#[derive(Clone, Debug, Default)]
pub struct Reflection {
    pub bindings: Vec<BindingInfo>,
    /// Members of the push-constant block, if the shader has one.
    pub push_constants: Option<Vec<MemberInfo>>,
    pub push_constant_size: u32,
    /// Named uniform-block layouts (by block type name), for layout tests.
    pub blocks: HashMap<String, Vec<MemberInfo>>,
    /// Specialisation constants: name -> SpecId.
    pub spec_constants: HashMap<String, u32>,
    pub local_size: [u32; 3],
}

#[derive(Clone, Debug)]
enum Ty {
    Scalar(u32),
    Vector(u32, u32), // component type, count
    Matrix(u32, u32), // column type, count
    Array(u32, u32),  // element type, length id
    RuntimeArray,
    Struct(Vec<u32>),
    Image { sampled: u32, dim: u32 },
    SampledImage,
    Sampler,
    Pointer(u32), // pointee
}

const OP_NAME: u32 = 5;
const OP_MEMBER_NAME: u32 = 6;
const OP_EXECUTION_MODE: u32 = 16;
const OP_TYPE_INT: u32 = 21;
const OP_TYPE_FLOAT: u32 = 22;
const OP_TYPE_VECTOR: u32 = 23;
const OP_TYPE_MATRIX: u32 = 24;
const OP_TYPE_IMAGE: u32 = 25;
const OP_TYPE_SAMPLER: u32 = 26;
const OP_TYPE_SAMPLED_IMAGE: u32 = 27;
const OP_TYPE_ARRAY: u32 = 28;
const OP_TYPE_RUNTIME_ARRAY: u32 = 29;
const OP_TYPE_STRUCT: u32 = 30;
const OP_TYPE_POINTER: u32 = 32;
const OP_CONSTANT: u32 = 43;
const OP_SPEC_CONSTANT_TRUE: u32 = 48;
const OP_SPEC_CONSTANT_FALSE: u32 = 49;
const OP_SPEC_CONSTANT: u32 = 50;
const OP_VARIABLE: u32 = 59;
const OP_DECORATE: u32 = 71;
const OP_MEMBER_DECORATE: u32 = 72;
const OP_EXECUTION_MODE_ID: u32 = 331;

const DEC_SPEC_ID: u32 = 1;
const DEC_BLOCK: u32 = 2;
const DEC_BUFFER_BLOCK: u32 = 3;
const DEC_ARRAY_STRIDE: u32 = 6;
const DEC_BINDING: u32 = 33;
const DEC_DESCRIPTOR_SET: u32 = 34;
const DEC_OFFSET: u32 = 35;

const SC_UNIFORM_CONSTANT: u32 = 0;
const SC_UNIFORM: u32 = 2;
const SC_PUSH_CONSTANT: u32 = 9;
const SC_STORAGE_BUFFER: u32 = 12;

fn string_at(words: &[u32]) -> String {
    let mut bytes = Vec::new();
    'outer: for w in words {
        for b in w.to_le_bytes() {
            if b == 0 {
                break 'outer;
            }
            bytes.push(b);
        }
    }
    String::from_utf8_lossy(&bytes).into_owned()
}

/// Parses `words` (a whole SPIR-V module).
pub fn reflect(words: &[u32]) -> Result<Reflection, String> {
    if words.len() < 5 || words[0] != 0x0723_0203 {
        return Err("not a SPIR-V module (bad magic number)".into());
    }
    let mut names: HashMap<u32, String> = HashMap::new();
    let mut member_names: HashMap<(u32, u32), String> = HashMap::new();
    let mut member_offsets: HashMap<(u32, u32), u32> = HashMap::new();
    let mut decorations: HashMap<(u32, u32), u32> = HashMap::new();
    let mut flags: HashMap<u32, Vec<u32>> = HashMap::new();
    let mut types: HashMap<u32, Ty> = HashMap::new();
    let mut constants: HashMap<u32, u32> = HashMap::new();
    let mut variables: Vec<(u32, u32, u32)> = Vec::new(); // id, pointer type, storage class
    let mut spec_ids: Vec<u32> = Vec::new();
    let mut local_size = [1, 1, 1];
    let mut local_size_ids: Option<[u32; 3]> = None;

    let mut i = 5;
    while i < words.len() {
        let count = (words[i] >> 16) as usize;
        let op = words[i] & 0xffff;
        if count == 0 || i + count > words.len() {
            return Err(format!("malformed instruction at word {i}"));
        }
        let a = &words[i + 1..i + count];
        match op {
            OP_NAME if !a.is_empty() => {
                names.insert(a[0], string_at(&a[1..]));
            }
            OP_MEMBER_NAME if a.len() >= 2 => {
                member_names.insert((a[0], a[1]), string_at(&a[2..]));
            }
            OP_EXECUTION_MODE if a.len() >= 5 && a[1] == 17 => {
                local_size = [a[2], a[3], a[4]];
            }
            OP_EXECUTION_MODE_ID if a.len() >= 5 && a[1] == 38 => {
                local_size_ids = Some([a[2], a[3], a[4]]);
            }
            OP_TYPE_INT | OP_TYPE_FLOAT if a.len() >= 2 => {
                types.insert(a[0], Ty::Scalar(a[1] / 8));
            }
            OP_TYPE_VECTOR if a.len() >= 3 => {
                types.insert(a[0], Ty::Vector(a[1], a[2]));
            }
            OP_TYPE_MATRIX if a.len() >= 3 => {
                types.insert(a[0], Ty::Matrix(a[1], a[2]));
            }
            OP_TYPE_IMAGE if a.len() >= 8 => {
                types.insert(
                    a[0],
                    Ty::Image {
                        sampled: a[6],
                        dim: a[2],
                    },
                );
            }
            OP_TYPE_SAMPLER if !a.is_empty() => {
                types.insert(a[0], Ty::Sampler);
            }
            OP_TYPE_SAMPLED_IMAGE if !a.is_empty() => {
                types.insert(a[0], Ty::SampledImage);
            }
            OP_TYPE_ARRAY if a.len() >= 3 => {
                types.insert(a[0], Ty::Array(a[1], a[2]));
            }
            OP_TYPE_RUNTIME_ARRAY if !a.is_empty() => {
                types.insert(a[0], Ty::RuntimeArray);
            }
            OP_TYPE_STRUCT if !a.is_empty() => {
                types.insert(a[0], Ty::Struct(a[1..].to_vec()));
            }
            OP_TYPE_POINTER if a.len() >= 3 => {
                types.insert(a[0], Ty::Pointer(a[2]));
            }
            OP_CONSTANT | OP_SPEC_CONSTANT if a.len() >= 3 => {
                constants.insert(a[1], a[2]);
                if op == OP_SPEC_CONSTANT {
                    spec_ids.push(a[1]);
                }
            }
            OP_SPEC_CONSTANT_TRUE | OP_SPEC_CONSTANT_FALSE if a.len() >= 2 => {
                spec_ids.push(a[1]);
            }
            OP_VARIABLE if a.len() >= 3 => {
                variables.push((a[1], a[0], a[2]));
            }
            OP_DECORATE if a.len() >= 2 => {
                let value = a.get(2).copied().unwrap_or(0);
                decorations.insert((a[0], a[1]), value);
                flags.entry(a[0]).or_default().push(a[1]);
            }
            OP_MEMBER_DECORATE if a.len() >= 4 && a[2] == DEC_OFFSET => {
                member_offsets.insert((a[0], a[1]), a[3]);
            }
            _ => {}
        }
        i += count;
    }
    if let Some(ids) = local_size_ids {
        for (k, id) in ids.iter().enumerate() {
            if let Some(&v) = constants.get(id) {
                local_size[k] = v;
            }
        }
    }

    let type_size =
        |ty: u32| -> u32 { size_of_type(ty, &types, &constants, &decorations, &member_offsets) };
    let struct_members = |struct_id: u32| -> Vec<MemberInfo> {
        let Some(Ty::Struct(members)) = types.get(&struct_id) else {
            return Vec::new();
        };
        members
            .iter()
            .enumerate()
            .map(|(m, &mty)| MemberInfo {
                name: member_names
                    .get(&(struct_id, m as u32))
                    .cloned()
                    .unwrap_or_default(),
                offset: member_offsets
                    .get(&(struct_id, m as u32))
                    .copied()
                    .unwrap_or(0),
                size: type_size(mty),
            })
            .collect()
    };

    let mut out = Reflection {
        local_size,
        ..Default::default()
    };
    for id in spec_ids {
        if let (Some(n), Some(&sid)) = (names.get(&id), decorations.get(&(id, DEC_SPEC_ID))) {
            out.spec_constants.insert(n.clone(), sid);
        }
    }
    for (id, ptr, sc) in variables {
        let Some(Ty::Pointer(pointee)) = types.get(&ptr) else {
            continue;
        };
        let pointee = *pointee;
        let var_name = names.get(&id).cloned().unwrap_or_default();
        let type_name = names.get(&pointee).cloned().unwrap_or_default();
        if sc == SC_PUSH_CONSTANT {
            let members = struct_members(pointee);
            out.push_constant_size = members.iter().map(|m| m.offset + m.size).max().unwrap_or(0);
            out.push_constants = Some(members);
            continue;
        }
        let (Some(&binding), set) = (
            decorations.get(&(id, DEC_BINDING)),
            decorations
                .get(&(id, DEC_DESCRIPTOR_SET))
                .copied()
                .unwrap_or(0),
        ) else {
            continue;
        };
        let has = |t: u32, d: u32| flags.get(&t).is_some_and(|v| v.contains(&d));
        let (ty, image_dim) = match (sc, types.get(&pointee)) {
            (SC_UNIFORM_CONSTANT, Some(Ty::SampledImage)) => {
                (vk::DescriptorType::COMBINED_IMAGE_SAMPLER, None)
            }
            (SC_UNIFORM_CONSTANT, Some(Ty::Image { sampled: 2, dim })) => {
                (vk::DescriptorType::STORAGE_IMAGE, Some(*dim))
            }
            (SC_UNIFORM_CONSTANT, Some(Ty::Image { dim, .. })) => {
                (vk::DescriptorType::SAMPLED_IMAGE, Some(*dim))
            }
            (SC_UNIFORM_CONSTANT, Some(Ty::Sampler)) => (vk::DescriptorType::SAMPLER, None),
            (SC_UNIFORM, _) if has(pointee, DEC_BUFFER_BLOCK) => {
                (vk::DescriptorType::STORAGE_BUFFER, None)
            }
            (SC_UNIFORM, _) if has(pointee, DEC_BLOCK) => {
                out.blocks
                    .insert(type_name.clone(), struct_members(pointee));
                (vk::DescriptorType::UNIFORM_BUFFER, None)
            }
            (SC_STORAGE_BUFFER, _) => (vk::DescriptorType::STORAGE_BUFFER, None),
            _ => continue,
        };
        let name = if var_name.is_empty() {
            type_name
        } else {
            var_name
        };
        out.bindings.push(BindingInfo {
            name,
            set,
            binding,
            ty,
            image_dim,
        });
    }
    out.bindings.sort_by_key(|b| (b.set, b.binding));
    Ok(out)
}

fn size_of_type(
    ty: u32,
    types: &HashMap<u32, Ty>,
    constants: &HashMap<u32, u32>,
    decorations: &HashMap<(u32, u32), u32>,
    member_offsets: &HashMap<(u32, u32), u32>,
) -> u32 {
    let rec = |t: u32| size_of_type(t, types, constants, decorations, member_offsets);
    match types.get(&ty) {
        Some(Ty::Scalar(bytes)) => *bytes,
        Some(Ty::Vector(c, n)) => rec(*c) * n,
        Some(Ty::Matrix(col, n)) => rec(*col).next_multiple_of(16) * n,
        Some(Ty::Array(e, len)) => {
            let stride = decorations
                .get(&(ty, DEC_ARRAY_STRIDE))
                .copied()
                .unwrap_or_else(|| rec(*e));
            stride * constants.get(len).copied().unwrap_or(1)
        }
        Some(Ty::Struct(members)) => members
            .iter()
            .enumerate()
            .map(|(m, &mt)| member_offsets.get(&(ty, m as u32)).copied().unwrap_or(0) + rec(mt))
            .max()
            .unwrap_or(0),
        _ => 0,
    }
}

/// Converts SPIR-V bytes (as embedded) to words.
pub fn words(bytes: &[u8]) -> Result<Vec<u32>, String> {
    ash::util::read_spv(&mut std::io::Cursor::new(bytes)).map_err(|e| e.to_string())
}
