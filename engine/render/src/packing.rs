//! Byte layouts shared with the shaders (`shaders/include/scene.glsl`): records
//! are built as 32-bit words so no `unsafe` casts are needed, and every record
//! is a multiple of 16 bytes so std140 and std430 agree.

use glam::{Mat4, Vec3, Vec4};

/// A growing list of 32-bit words in the layout a shader block expects.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Words(pub Vec<u32>);

impl Words {
    /// Appends one float.
    pub fn f32(&mut self, v: f32) -> &mut Self {
        self.0.push(v.to_bits());
        self
    }

    /// Appends one unsigned integer.
    pub fn u32(&mut self, v: u32) -> &mut Self {
        self.0.push(v);
        self
    }

    /// Appends a vec4.
    pub fn vec4(&mut self, v: Vec4) -> &mut Self {
        for c in v.to_array() {
            self.f32(c);
        }
        self
    }

    /// Appends a vec3 and a fourth component, as one vec4 slot.
    pub fn vec3w(&mut self, v: Vec3, w: f32) -> &mut Self {
        self.vec4(v.extend(w))
    }

    /// Appends a column-major mat4.
    pub fn mat4(&mut self, m: &Mat4) -> &mut Self {
        for c in m.to_cols_array() {
            self.f32(c);
        }
        self
    }

    /// The little-endian bytes, for uploading.
    pub fn bytes(&self) -> Vec<u8> {
        self.0.iter().flat_map(|w| w.to_le_bytes()).collect()
    }

    /// Length in bytes.
    pub fn byte_len(&self) -> usize {
        self.0.len() * 4
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packs_in_order_little_endian() {
        let mut w = Words::default();
        w.f32(1.0).u32(7).vec3w(Vec3::new(2.0, 3.0, 4.0), 5.0);
        assert_eq!(w.byte_len(), 24);
        let b = w.bytes();
        assert_eq!(&b[0..4], &1.0f32.to_le_bytes());
        assert_eq!(&b[4..8], &7u32.to_le_bytes());
        assert_eq!(&b[20..24], &5.0f32.to_le_bytes());
        let mut m = Words::default();
        m.mat4(&Mat4::from_translation(Vec3::new(9.0, 8.0, 7.0)));
        assert_eq!(f32::from_bits(m.0[12]), 9.0);
        assert_eq!(f32::from_bits(m.0[14]), 7.0);
    }
}
