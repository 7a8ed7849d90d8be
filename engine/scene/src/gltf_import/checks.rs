//! What a glTF file must satisfy before any of it is read: a GLB header whose
//! length is the file's, accessors held to their views and buffers (a reader
//! that finds one out of range returns nothing, which would import silently
//! wrong geometry), and a node graph whose expansion into placed meshes is
//! counted before it is walked (a node listed twice as a child doubles
//! everything below it).

use crate::error::{Diagnostics, Location};
use std::path::Path;

/// The most node instances one file may expand to (a node placed once per
/// path from a scene root to it). Each becomes meshes weft draws one call
/// apiece: a file at this many loads in about a second; the real models in
/// `../shared/assets` have at most a few thousand.
pub const MAX_NODE_INSTANCES: u64 = 100_000;
/// The most triangles one file may expand to once every node is placed,
/// each primitive counted by its largest accessor (vertices or indices).
pub const MAX_EXPANDED_TRIANGLES: u64 = 50_000_000;

/// A GLB's header: its `length` must be the file's size (glTF 2.0 §4.4.2).
pub(super) fn check_glb_header(bytes: &[u8]) -> Result<(), String> {
    if bytes.len() < 12 || &bytes[..4] != b"glTF" {
        return Ok(());
    }
    let length = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]);
    if u64::from(length) != bytes.len() as u64 {
        return Err(format!(
            "the GLB header gives a length of {length} bytes, but the file has {}",
            bytes.len()
        ));
    }
    Ok(())
}

/// `accessor` within its view, the view within its buffer, the stride at
/// least one element, and a sparse accessor's indices within the accessor
/// (glTF 2.0 §3.6.2 and §5.1).
pub(super) fn check_accessor_bounds(
    accessor: &gltf::Accessor<'_>,
    buffers: &[Vec<u8>],
) -> Result<(), String> {
    let name = format!("accessor {}", accessor.index());
    let count = accessor.count() as u64;
    if count == 0 {
        return Err(format!(
            "{name} has a count of 0; glTF 2.0 requires at least 1"
        ));
    }
    let element = accessor.size() as u64;
    if let Some(view) = accessor.view() {
        let stride = view_within_buffer(&view, buffers, element)?;
        let end = span(accessor.offset() as u64, stride, count, element);
        if end > view.length() as u64 {
            return Err(format!(
                "{name} needs {end} bytes of buffer view {} ({count} elements of {element} bytes, stride {stride}, offset {}), which has {}",
                view.index(),
                accessor.offset(),
                view.length()
            ));
        }
    }
    if let Some(sparse) = accessor.sparse() {
        check_sparse(&name, &sparse, count, element, buffers)?;
    }
    Ok(())
}

/// The view within its buffer and its stride (or the element's size) at
/// least `element` bytes; returns the stride.
fn view_within_buffer(
    view: &gltf::buffer::View<'_>,
    buffers: &[Vec<u8>],
    element: u64,
) -> Result<u64, String> {
    let buffer = view.buffer();
    let end = (view.offset() as u64).saturating_add(view.length() as u64);
    let available = buffers.get(buffer.index()).map_or(0, |b| b.len() as u64);
    if end > available.min(buffer.length() as u64) {
        return Err(format!(
            "buffer view {} ends at byte {end}, past buffer {}'s {} bytes",
            view.index(),
            buffer.index(),
            buffer.length()
        ));
    }
    let stride = view.stride().map_or(element, |s| s as u64);
    if stride < element {
        return Err(format!(
            "buffer view {} has a byteStride of {stride}, less than its {element}-byte elements",
            view.index()
        ));
    }
    Ok(stride)
}

/// A sparse accessor's indices and values within their views, at most
/// `count` of them, each index below `count` and increasing.
fn check_sparse(
    name: &str,
    sparse: &gltf::accessor::sparse::Sparse<'_>,
    count: u64,
    element: u64,
    buffers: &[Vec<u8>],
) -> Result<(), String> {
    let sparse_count = sparse.count() as u64;
    if sparse_count == 0 || sparse_count > count {
        return Err(format!(
            "{name} has {sparse_count} sparse values for {count} elements"
        ));
    }
    let values = sparse.values();
    let values_end = span(values.offset() as u64, element, sparse_count, element);
    view_within_buffer(&values.view(), buffers, element)?;
    if values_end > values.view().length() as u64 {
        return Err(format!(
            "{name}'s sparse values need {values_end} bytes of buffer view {}, which has {}",
            values.view().index(),
            values.view().length()
        ));
    }
    let indices = sparse.indices();
    let view = indices.view();
    let size = indices.index_type().size() as u64;
    view_within_buffer(&view, buffers, size)?;
    let start = (view.offset() as u64).saturating_add(indices.offset() as u64);
    let end = span(indices.offset() as u64, size, sparse_count, size);
    if end > view.length() as u64 {
        return Err(format!(
            "{name}'s sparse indices need {end} bytes of buffer view {}, which has {}",
            view.index(),
            view.length()
        ));
    }
    let bytes = &buffers[view.buffer().index()];
    let mut previous: Option<u64> = None;
    for i in 0..sparse_count {
        let at = (start + i * size) as usize;
        let index = match size {
            1 => u64::from(bytes[at]),
            2 => u64::from(u16::from_le_bytes([bytes[at], bytes[at + 1]])),
            _ => u64::from(u32::from_le_bytes([
                bytes[at],
                bytes[at + 1],
                bytes[at + 2],
                bytes[at + 3],
            ])),
        };
        if index >= count {
            return Err(format!(
                "{name}'s sparse index {index} is past its {count} elements"
            ));
        }
        if previous.is_some_and(|p| index <= p) {
            return Err(format!(
                "{name}'s sparse indices are not strictly increasing ({index} after {})",
                previous.unwrap_or_default()
            ));
        }
        previous = Some(index);
    }
    Ok(())
}

/// The end of `count` elements of `element` bytes, `stride` apart, from
/// `offset` (saturating: a count or offset from a hostile file cannot wrap).
fn span(offset: u64, stride: u64, count: u64, element: u64) -> u64 {
    offset
        .saturating_add(stride.saturating_mul(count.saturating_sub(1)))
        .saturating_add(element)
}

/// Node instances and triangles below one node, counted once per node.
#[derive(Clone, Copy, Default)]
struct Expansion {
    nodes: u64,
    triangles: u64,
}

impl Expansion {
    /// Both counts added, saturating.
    fn plus(self, other: Self) -> Self {
        Self {
            nodes: self.nodes.saturating_add(other.nodes),
            triangles: self.triangles.saturating_add(other.triangles),
        }
    }
}

/// Counts what walking the node graph from `roots` would place, before it
/// is walked: more than [`MAX_NODE_INSTANCES`] nodes or
/// [`MAX_EXPANDED_TRIANGLES`] triangles, or a cycle, is an error naming a
/// node with more than one parent. A node with several parents (which glTF
/// 2.0 forbids, §3.5.3) is placed once per parent, with a warning.
pub(super) fn check_node_graph(
    doc: &gltf::Document,
    roots: &[gltf::Node<'_>],
    path: &Path,
    diag: &mut Diagnostics,
) -> Result<(), String> {
    let count = doc.nodes().len();
    let mut parents = vec![0u64; count];
    for node in doc.nodes() {
        for child in node.children() {
            parents[child.index()] += 1;
        }
    }
    for root in roots {
        parents[root.index()] += 1;
    }
    let shared: Vec<usize> = (0..count).filter(|&i| parents[i] > 1).collect();
    let shared_text = || match shared.first() {
        Some(&i) => format!(
            "; node {i} has {} parents (or is listed twice), where glTF 2.0 allows one",
            parents[i]
        ),
        None => String::new(),
    };
    let nodes: Vec<gltf::Node<'_>> = doc.nodes().collect();
    let mut memo: Vec<Option<Expansion>> = vec![None; count];
    let mut on_path = vec![false; count];
    let mut total = Expansion::default();
    for root in roots {
        let below = expand(root.index(), &nodes, &mut memo, &mut on_path)
            .map_err(|node| format!("the node hierarchy has a cycle through node {node}"))?;
        total = total.plus(below);
    }
    if total.nodes > MAX_NODE_INSTANCES {
        return Err(format!(
            "the node hierarchy expands to {} node instances, over the limit of {MAX_NODE_INSTANCES}{}",
            shown(total.nodes),
            shared_text()
        ));
    }
    if total.triangles > MAX_EXPANDED_TRIANGLES {
        return Err(format!(
            "the node hierarchy places {} triangles (each primitive counted by its largest accessor, vertices or indices), over the limit of {MAX_EXPANDED_TRIANGLES}{}",
            shown(total.triangles),
            shared_text()
        ));
    }
    for &i in &shared {
        diag.warn(
            Location::file(path),
            format!(
                "node {i} has {} parents (or is listed twice), where glTF 2.0 allows one: it is placed once per parent",
                parents[i]
            ),
        );
    }
    Ok(())
}

/// A saturated count shown as "more than" the largest u64.
fn shown(count: u64) -> String {
    if count == u64::MAX {
        format!("more than {}", u64::MAX - 1)
    } else {
        count.to_string()
    }
}

/// The expansion below `node` (itself included), memoised; `Err(node)` on a
/// cycle. Iterative, so a deep chain cannot overflow the stack.
fn expand(
    node: usize,
    nodes: &[gltf::Node<'_>],
    memo: &mut [Option<Expansion>],
    on_path: &mut [bool],
) -> Result<Expansion, usize> {
    let mut stack: Vec<(usize, bool)> = vec![(node, false)];
    while let Some((at, children_done)) = stack.pop() {
        if memo[at].is_some() {
            continue;
        }
        if children_done {
            let own = Expansion {
                nodes: 1,
                triangles: own_triangles(&nodes[at]),
            };
            let sum = nodes[at]
                .children()
                .map(|child| memo[child.index()].unwrap_or_default())
                .fold(own, Expansion::plus);
            memo[at] = Some(sum);
            on_path[at] = false;
            continue;
        }
        if on_path[at] {
            return Err(at);
        }
        on_path[at] = true;
        stack.push((at, true));
        for child in nodes[at].children() {
            let c = child.index();
            if on_path[c] {
                return Err(c);
            }
            if memo[c].is_none() {
                stack.push((c, false));
            }
        }
    }
    Ok(memo[node].unwrap_or_default())
}

/// The triangles the mesh `node` places, counted by what reading it costs:
/// per triangle primitive, its largest accessor (indices or any attribute,
/// each read whole) over three, rounded up. A sparse accessor without a
/// view may declare any count, and a few indices may index a huge vertex
/// buffer: both are counted.
fn own_triangles(node: &gltf::Node<'_>) -> u64 {
    node.mesh().map_or(0, |mesh| {
        mesh.primitives()
            .filter(|p| p.mode() == gltf::mesh::Mode::Triangles)
            .map(|p| {
                let largest = p
                    .attributes()
                    .map(|(_, a)| a)
                    .chain(p.indices())
                    .map(|a| a.count() as u64)
                    .max()
                    .unwrap_or(0);
                largest.div_ceil(3)
            })
            .fold(0u64, u64::saturating_add)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glb_header_length_must_be_the_files() {
        let mut glb = b"glTF".to_vec();
        glb.extend_from_slice(&2u32.to_le_bytes());
        glb.extend_from_slice(&20u32.to_le_bytes());
        glb.extend_from_slice(&[0; 16]);
        assert_eq!(
            check_glb_header(&glb).unwrap_err(),
            "the GLB header gives a length of 20 bytes, but the file has 28"
        );
        glb[8..12].copy_from_slice(&28u32.to_le_bytes());
        assert_eq!(check_glb_header(&glb), Ok(()));
        assert_eq!(check_glb_header(b"{\"asset\":{}}"), Ok(()));
    }
}
