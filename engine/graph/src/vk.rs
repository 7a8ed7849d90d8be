//! Vulkan vocabulary as plain data: pipeline stages, access masks, layouts and
//! formats with the numeric values of the Vulkan headers, so a compiled plan can be
//! inspected and tested without a Vulkan library and converted with `from_raw`.

use bitflags::bitflags;
use serde::{Deserialize, Serialize};

bitflags! {
    /// `VkPipelineStageFlags2`: where in the pipeline an access happens.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
    pub struct Stage: u64 {
        const TOP_OF_PIPE = 0x1;
        const DRAW_INDIRECT = 0x2;
        const VERTEX_INPUT = 0x4;
        const VERTEX_SHADER = 0x8;
        const FRAGMENT_SHADER = 0x80;
        const EARLY_FRAGMENT_TESTS = 0x100;
        const LATE_FRAGMENT_TESTS = 0x200;
        const COLOR_ATTACHMENT_OUTPUT = 0x400;
        const COMPUTE_SHADER = 0x800;
        const ALL_TRANSFER = 0x1000;
        const BOTTOM_OF_PIPE = 0x2000;
        const ACCELERATION_STRUCTURE_BUILD = 0x0200_0000;
        const COPY = 0x1_0000_0000;
        const BLIT = 0x4_0000_0000;
        const CLEAR = 0x8_0000_0000;
    }
}

bitflags! {
    /// `VkAccessFlags2`: what kind of memory access happens.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
    pub struct Access: u64 {
        const INDIRECT_COMMAND_READ = 0x1;
        const UNIFORM_READ = 0x8;
        const SHADER_READ = 0x20;
        const SHADER_WRITE = 0x40;
        const COLOR_ATTACHMENT_READ = 0x80;
        const COLOR_ATTACHMENT_WRITE = 0x100;
        const DEPTH_STENCIL_ATTACHMENT_READ = 0x200;
        const DEPTH_STENCIL_ATTACHMENT_WRITE = 0x400;
        const TRANSFER_READ = 0x800;
        const TRANSFER_WRITE = 0x1000;
        const ACCELERATION_STRUCTURE_READ = 0x0020_0000;
        const ACCELERATION_STRUCTURE_WRITE = 0x0040_0000;
        const SHADER_SAMPLED_READ = 0x1_0000_0000;
        const SHADER_STORAGE_READ = 0x2_0000_0000;
        const SHADER_STORAGE_WRITE = 0x4_0000_0000;
    }
}

impl Access {
    /// The access bits that write memory; any of them makes an access a write.
    pub const WRITES: Access = Access::SHADER_WRITE
        .union(Access::COLOR_ATTACHMENT_WRITE)
        .union(Access::DEPTH_STENCIL_ATTACHMENT_WRITE)
        .union(Access::TRANSFER_WRITE)
        .union(Access::SHADER_STORAGE_WRITE)
        .union(Access::ACCELERATION_STRUCTURE_WRITE);

    /// Whether any bit of this mask writes memory.
    pub fn is_write(self) -> bool {
        self.intersects(Access::WRITES)
    }
}

bitflags! {
    /// `VkImageUsageFlags`: how an image is used over the whole frame, for image creation.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
    pub struct ImageUsage: u32 {
        const TRANSFER_SRC = 0x1;
        const TRANSFER_DST = 0x2;
        const SAMPLED = 0x4;
        const STORAGE = 0x8;
        const COLOR_ATTACHMENT = 0x10;
        const DEPTH_STENCIL_ATTACHMENT = 0x20;
    }
}

bitflags! {
    /// `VkBufferUsageFlags`: how a buffer is used over the whole frame.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
    pub struct BufferUsage: u32 {
        const TRANSFER_SRC = 0x1;
        const TRANSFER_DST = 0x2;
        const UNIFORM = 0x10;
        const STORAGE = 0x20;
        const INDIRECT = 0x100;
        /// An acceleration-structure build's scratch is addressed by device address.
        const SHADER_DEVICE_ADDRESS = 0x20000;
    }
}

/// `VkImageLayout` values the compiler emits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[repr(i32)]
pub enum Layout {
    Undefined = 0,
    General = 1,
    ColorAttachmentOptimal = 2,
    DepthStencilAttachmentOptimal = 3,
    DepthStencilReadOnlyOptimal = 4,
    ShaderReadOnlyOptimal = 5,
    TransferSrcOptimal = 6,
    TransferDstOptimal = 7,
}

impl Layout {
    /// The `VkImageLayout` value.
    pub fn raw(self) -> i32 {
        self as i32
    }

    /// The Vulkan spelling, for plans people read.
    pub fn vk_name(self) -> &'static str {
        match self {
            Layout::Undefined => "UNDEFINED",
            Layout::General => "GENERAL",
            Layout::ColorAttachmentOptimal => "COLOR_ATTACHMENT_OPTIMAL",
            Layout::DepthStencilAttachmentOptimal => "DEPTH_STENCIL_ATTACHMENT_OPTIMAL",
            Layout::DepthStencilReadOnlyOptimal => "DEPTH_STENCIL_READ_ONLY_OPTIMAL",
            Layout::ShaderReadOnlyOptimal => "SHADER_READ_ONLY_OPTIMAL",
            Layout::TransferSrcOptimal => "TRANSFER_SRC_OPTIMAL",
            Layout::TransferDstOptimal => "TRANSFER_DST_OPTIMAL",
        }
    }
}

/// Image aspect of a format, which decides attachment kind and barrier aspect masks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Aspect {
    Color,
    Depth,
    DepthStencil,
}

bitflags! {
    /// Format features the Vulkan specification guarantees for every device
    /// ("mandatory format support"); validation relies on these alone so a graph
    /// that checks clean is portable.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
    pub struct FormatFeatures: u32 {
        const SAMPLED = 1;
        const FILTER_LINEAR = 2;
        const STORAGE = 4;
        const COLOR_ATTACHMENT = 8;
        const BLEND = 16;
        const DEPTH_ATTACHMENT = 32;
    }
}

/// One image format the engine knows, by its Vulkan name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FormatInfo {
    /// Vulkan name without the `VK_FORMAT_` prefix.
    pub name: &'static str,
    /// `VkFormat` value.
    pub raw: i32,
    /// Bytes per texel.
    pub bytes: u32,
    /// Colour, depth, or depth+stencil.
    pub aspect: Aspect,
    /// Features guaranteed on every Vulkan 1.3 device.
    pub guaranteed: FormatFeatures,
}

const S: FormatFeatures = FormatFeatures::SAMPLED;
const L: FormatFeatures = FormatFeatures::FILTER_LINEAR;
const ST: FormatFeatures = FormatFeatures::STORAGE;
const C: FormatFeatures = FormatFeatures::COLOR_ATTACHMENT;
const B: FormatFeatures = FormatFeatures::BLEND;
const D: FormatFeatures = FormatFeatures::DEPTH_ATTACHMENT;

const fn f(
    name: &'static str,
    raw: i32,
    bytes: u32,
    aspect: Aspect,
    guaranteed: FormatFeatures,
) -> FormatInfo {
    FormatInfo {
        name,
        raw,
        bytes,
        aspect,
        guaranteed,
    }
}

/// The formats a graph may name, with their mandatory support from the Vulkan
/// 1.3 specification's format tables.
pub const FORMATS: &[FormatInfo] = &[
    f(
        "R8_UNORM",
        9,
        1,
        Aspect::Color,
        S.union(L).union(C).union(B),
    ),
    f("R8_UINT", 13, 1, Aspect::Color, S.union(C)),
    f(
        "R8G8_UNORM",
        16,
        2,
        Aspect::Color,
        S.union(L).union(C).union(B),
    ),
    f("R8G8_SNORM", 17, 2, Aspect::Color, S.union(L)),
    f(
        "R8G8B8A8_UNORM",
        37,
        4,
        Aspect::Color,
        S.union(L).union(C).union(B).union(ST),
    ),
    f("R8G8B8A8_SNORM", 38, 4, Aspect::Color, S.union(L).union(ST)),
    f(
        "R8G8B8A8_SRGB",
        43,
        4,
        Aspect::Color,
        S.union(L).union(C).union(B),
    ),
    f(
        "B8G8R8A8_UNORM",
        44,
        4,
        Aspect::Color,
        S.union(L).union(C).union(B),
    ),
    f(
        "B8G8R8A8_SRGB",
        50,
        4,
        Aspect::Color,
        S.union(L).union(C).union(B),
    ),
    f(
        "A2B10G10R10_UNORM_PACK32",
        64,
        4,
        Aspect::Color,
        S.union(L).union(C).union(B),
    ),
    f("R16_UNORM", 70, 2, Aspect::Color, S.union(L)),
    f("R16_UINT", 74, 2, Aspect::Color, S.union(C)),
    f(
        "R16_SFLOAT",
        76,
        2,
        Aspect::Color,
        S.union(L).union(C).union(B),
    ),
    f("R16G16_UNORM", 77, 4, Aspect::Color, S.union(L)),
    f("R16G16_SNORM", 78, 4, Aspect::Color, S.union(L)),
    f(
        "R16G16_SFLOAT",
        83,
        4,
        Aspect::Color,
        S.union(L).union(C).union(B),
    ),
    f("R16G16B16A16_UNORM", 91, 8, Aspect::Color, S.union(L)),
    f(
        "R16G16B16A16_SFLOAT",
        97,
        8,
        Aspect::Color,
        S.union(L).union(C).union(B).union(ST),
    ),
    f("R32_UINT", 98, 4, Aspect::Color, S.union(C).union(ST)),
    f("R32_SINT", 99, 4, Aspect::Color, S.union(C).union(ST)),
    f("R32_SFLOAT", 100, 4, Aspect::Color, S.union(C).union(ST)),
    f("R32G32_UINT", 101, 8, Aspect::Color, S.union(C).union(ST)),
    f("R32G32_SFLOAT", 103, 8, Aspect::Color, S.union(C).union(ST)),
    f(
        "R32G32B32A32_UINT",
        107,
        16,
        Aspect::Color,
        S.union(C).union(ST),
    ),
    f(
        "R32G32B32A32_SFLOAT",
        109,
        16,
        Aspect::Color,
        S.union(C).union(ST),
    ),
    f("B10G11R11_UFLOAT_PACK32", 122, 4, Aspect::Color, S.union(L)),
    f("E5B9G9R9_UFLOAT_PACK32", 123, 4, Aspect::Color, S.union(L)),
    f("D16_UNORM", 124, 2, Aspect::Depth, S.union(D)),
    f("D32_SFLOAT", 126, 4, Aspect::Depth, S.union(D)),
    f("D24_UNORM_S8_UINT", 129, 4, Aspect::DepthStencil, D),
    f("D32_SFLOAT_S8_UINT", 130, 8, Aspect::DepthStencil, D),
];

/// Looks up a format by its Vulkan name (with or without `VK_FORMAT_`).
pub fn format_by_name(name: &str) -> Option<&'static FormatInfo> {
    let name = name.strip_prefix("VK_FORMAT_").unwrap_or(name);
    FORMATS.iter().find(|f| f.name == name)
}

/// Writes a flag set with its Vulkan spellings joined by `|`, or `NONE`.
pub fn flag_names<T: bitflags::Flags>(flags: T) -> String {
    let names: Vec<&str> = flags.iter_names().map(|(n, _)| n).collect();
    if names.is_empty() {
        "NONE".to_string()
    } else {
        names.join("|")
    }
}
