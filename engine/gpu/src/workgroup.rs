//! What a compute shader asks of the device beyond capabilities, read from
//! its SPIR-V: the workgroup size (`LocalSize`, `LocalSizeId` or the
//! `WorkgroupSize` built-in, which wins) and the bytes of its `shared`
//! variables. Vulkan bounds both (`maxComputeWorkGroupSize`,
//! `maxComputeWorkGroupInvocations`, `maxComputeSharedMemorySize`), and
//! drivers are not required to refuse a module that breaks them.

use std::collections::HashMap;

const OP_EXECUTION_MODE: u32 = 16;
const OP_EXECUTION_MODE_ID: u32 = 331;
const OP_TYPE_BOOL: u32 = 20;
const OP_TYPE_INT: u32 = 21;
const OP_TYPE_FLOAT: u32 = 22;
const OP_TYPE_VECTOR: u32 = 23;
const OP_TYPE_MATRIX: u32 = 24;
const OP_TYPE_ARRAY: u32 = 28;
const OP_TYPE_STRUCT: u32 = 30;
const OP_TYPE_POINTER: u32 = 32;
const OP_CONSTANT: u32 = 43;
const OP_CONSTANT_COMPOSITE: u32 = 44;
const OP_SPEC_CONSTANT: u32 = 50;
const OP_SPEC_CONSTANT_COMPOSITE: u32 = 51;
const OP_VARIABLE: u32 = 59;
const OP_DECORATE: u32 = 71;
const OP_MEMBER_DECORATE: u32 = 72;
const MODE_LOCAL_SIZE: u32 = 17;
const MODE_LOCAL_SIZE_ID: u32 = 38;
const DECORATION_BUILT_IN: u32 = 11;
const DECORATION_OFFSET: u32 = 35;
const BUILT_IN_WORKGROUP_SIZE: u32 = 25;
const STORAGE_WORKGROUP: u32 = 4;

/// A compute shader's demands.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Workgroup {
    /// Invocations per workgroup along x, y and z.
    pub size: [u32; 3],
    /// Bytes of `shared` (Workgroup storage class) variables.
    pub shared_bytes: u64,
}

/// A type's size in bytes, as Vulkan counts shared memory: scalars by their
/// width (booleans as 4 bytes), arrays by length, structs to the end of their
/// last member (by `Offset` where decorated).
#[derive(Default)]
struct Types {
    size: HashMap<u32, u64>,
    constants: HashMap<u32, u64>,
    composites: HashMap<u32, Vec<u32>>,
    member_offsets: HashMap<(u32, u32), u64>,
    pointers: HashMap<u32, (u32, u32)>,
}

impl Types {
    fn of(&self, id: u32) -> u64 {
        self.size.get(&id).copied().unwrap_or(0)
    }
}

/// Reads the workgroup size and shared bytes of `spirv`; a module whose
/// instructions run past its end yields what was read up to there.
pub fn read(spirv: &[u32]) -> Workgroup {
    let mut types = Types::default();
    let mut workgroup = Workgroup::default();
    let mut size_ids: Option<[u32; 3]> = None;
    let mut builtin_size: Option<u32> = None;
    let mut shared: Vec<u32> = Vec::new();
    let mut at = 5;
    while let Some(&word) = spirv.get(at) {
        let (count, opcode) = ((word >> 16) as usize, word & 0xffff);
        if count == 0 || at + count > spirv.len() {
            break;
        }
        let ops = &spirv[at + 1..at + count];
        let op = |i: usize| ops.get(i).copied().unwrap_or(0);
        match opcode {
            OP_EXECUTION_MODE if op(1) == MODE_LOCAL_SIZE && ops.len() >= 5 => {
                workgroup.size = [op(2), op(3), op(4)];
            }
            OP_EXECUTION_MODE_ID if op(1) == MODE_LOCAL_SIZE_ID && ops.len() >= 5 => {
                size_ids = Some([op(2), op(3), op(4)]);
            }
            OP_DECORATE if op(1) == DECORATION_BUILT_IN && op(2) == BUILT_IN_WORKGROUP_SIZE => {
                builtin_size = Some(op(0));
            }
            OP_MEMBER_DECORATE if op(2) == DECORATION_OFFSET => {
                types
                    .member_offsets
                    .insert((op(0), op(1)), u64::from(op(3)));
            }
            OP_TYPE_BOOL => {
                types.size.insert(op(0), 4);
            }
            OP_TYPE_INT | OP_TYPE_FLOAT => {
                types.size.insert(op(0), u64::from(op(1)) / 8);
            }
            OP_TYPE_VECTOR | OP_TYPE_MATRIX => {
                let size = types.of(op(1)) * u64::from(op(2));
                types.size.insert(op(0), size);
            }
            OP_TYPE_ARRAY => {
                let length = types.constants.get(&op(2)).copied().unwrap_or(0);
                let size = types.of(op(1)).saturating_mul(length);
                types.size.insert(op(0), size);
            }
            OP_TYPE_STRUCT => {
                let id = op(0);
                let mut end = 0u64;
                for (i, &member) in ops[1..].iter().enumerate() {
                    let start = types
                        .member_offsets
                        .get(&(id, i as u32))
                        .copied()
                        .unwrap_or(end);
                    end = end.max(start.saturating_add(types.of(member)));
                }
                types.size.insert(id, end);
            }
            OP_TYPE_POINTER => {
                types.pointers.insert(op(0), (op(1), op(2)));
            }
            OP_CONSTANT | OP_SPEC_CONSTANT => {
                types.constants.insert(op(1), u64::from(op(2)));
            }
            OP_CONSTANT_COMPOSITE | OP_SPEC_CONSTANT_COMPOSITE => {
                types.composites.insert(op(1), ops[2..].to_vec());
            }
            OP_VARIABLE if op(2) == STORAGE_WORKGROUP => {
                shared.push(op(0));
            }
            _ => {}
        }
        at += count;
    }
    let constant = |id: &u32| types.constants.get(id).copied().unwrap_or(0) as u32;
    if let Some(ids) = size_ids {
        workgroup.size = ids.map(|id| constant(&id));
    }
    if let Some(parts) = builtin_size.and_then(|id| types.composites.get(&id)) {
        if parts.len() == 3 {
            workgroup.size = [
                constant(&parts[0]),
                constant(&parts[1]),
                constant(&parts[2]),
            ];
        }
    }
    workgroup.shared_bytes = shared
        .iter()
        .filter_map(|pointer| types.pointers.get(pointer))
        .map(|&(_, pointee)| types.of(pointee))
        .sum();
    workgroup
}
