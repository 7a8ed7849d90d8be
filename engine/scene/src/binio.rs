//! A small little-endian binary encoding for the model cache: every read is bounds-checked
//! and fails with `None` instead of panicking, so a damaged cache file is just a miss.

use glam::{Mat4, Quat, Vec2, Vec3, Vec4};
use std::path::PathBuf;
use std::sync::Arc;

/// Appends encoded values to a byte vector.
#[derive(Default)]
pub(crate) struct Writer {
    /// The bytes so far.
    pub bytes: Vec<u8>,
}

/// Reads encoded values from a byte slice.
pub(crate) struct Reader<'a> {
    bytes: &'a [u8],
}

impl<'a> Reader<'a> {
    /// Starts reading `bytes`.
    pub(crate) fn new(bytes: &'a [u8]) -> Self {
        Self { bytes }
    }

    /// Takes the next `n` bytes.
    pub(crate) fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        if n > self.bytes.len() {
            return None;
        }
        let (head, tail) = self.bytes.split_at(n);
        self.bytes = tail;
        Some(head)
    }

    /// Whether everything was read.
    pub(crate) fn is_empty(&self) -> bool {
        self.bytes.is_empty()
    }

    /// A length prefix, refused when even one byte per item would overrun the input.
    fn len(&mut self) -> Option<usize> {
        let n = usize::try_from(u64::read(self)?).ok()?;
        (n <= self.bytes.len()).then_some(n)
    }
}

/// A value with a binary encoding.
pub(crate) trait Bin: Sized {
    /// Appends the encoding.
    fn write(&self, w: &mut Writer);
    /// Reads one value, `None` on truncated or invalid input.
    fn read(r: &mut Reader<'_>) -> Option<Self>;
}

macro_rules! bin_number {
    ($($t:ty),*) => {$(
        impl Bin for $t {
            fn write(&self, w: &mut Writer) {
                w.bytes.extend_from_slice(&self.to_le_bytes());
            }
            fn read(r: &mut Reader<'_>) -> Option<Self> {
                Some(<$t>::from_le_bytes(r.take(std::mem::size_of::<$t>())?.try_into().ok()?))
            }
        }
    )*};
}
bin_number!(u8, u32, u64, f32);

impl Bin for bool {
    fn write(&self, w: &mut Writer) {
        u8::from(*self).write(w);
    }
    fn read(r: &mut Reader<'_>) -> Option<Self> {
        match u8::read(r)? {
            0 => Some(false),
            1 => Some(true),
            _ => None,
        }
    }
}

impl Bin for usize {
    fn write(&self, w: &mut Writer) {
        (*self as u64).write(w);
    }
    fn read(r: &mut Reader<'_>) -> Option<Self> {
        usize::try_from(u64::read(r)?).ok()
    }
}

impl Bin for String {
    fn write(&self, w: &mut Writer) {
        self.len().write(w);
        w.bytes.extend_from_slice(self.as_bytes());
    }
    fn read(r: &mut Reader<'_>) -> Option<Self> {
        let n = r.len()?;
        String::from_utf8(r.take(n)?.to_vec()).ok()
    }
}

impl Bin for PathBuf {
    fn write(&self, w: &mut Writer) {
        self.to_string_lossy().into_owned().write(w);
    }
    fn read(r: &mut Reader<'_>) -> Option<Self> {
        String::read(r).map(PathBuf::from)
    }
}

impl Bin for Arc<[u8]> {
    fn write(&self, w: &mut Writer) {
        self.len().write(w);
        w.bytes.extend_from_slice(self);
    }
    fn read(r: &mut Reader<'_>) -> Option<Self> {
        let n = r.len()?;
        Some(r.take(n)?.into())
    }
}

impl<T: Bin> Bin for Option<T> {
    fn write(&self, w: &mut Writer) {
        match self {
            Some(v) => {
                true.write(w);
                v.write(w);
            }
            None => false.write(w),
        }
    }
    fn read(r: &mut Reader<'_>) -> Option<Self> {
        if bool::read(r)? {
            Some(Some(T::read(r)?))
        } else {
            Some(None)
        }
    }
}

impl<T: Bin> Bin for Vec<T> {
    fn write(&self, w: &mut Writer) {
        self.len().write(w);
        for v in self {
            v.write(w);
        }
    }
    fn read(r: &mut Reader<'_>) -> Option<Self> {
        let n = r.len()?;
        (0..n).map(|_| T::read(r)).collect()
    }
}

/// Encodes a glam type as its float array.
macro_rules! bin_floats {
    ($($t:ty => $n:expr),*) => {$(
        impl Bin for $t {
            fn write(&self, w: &mut Writer) {
                for f in self.to_array() {
                    f.write(w);
                }
            }
            fn read(r: &mut Reader<'_>) -> Option<Self> {
                let mut a = [0f32; $n];
                for f in &mut a {
                    *f = f32::read(r)?;
                }
                Some(<$t>::from_array(a))
            }
        }
    )*};
}
bin_floats!(Vec2 => 2, Vec3 => 3, Vec4 => 4, Quat => 4);

impl Bin for Mat4 {
    fn write(&self, w: &mut Writer) {
        for f in self.to_cols_array() {
            f.write(w);
        }
    }
    fn read(r: &mut Reader<'_>) -> Option<Self> {
        let mut a = [0f32; 16];
        for f in &mut a {
            *f = f32::read(r)?;
        }
        Some(Mat4::from_cols_array(&a))
    }
}

/// Implements [`Bin`] for a struct by encoding the listed fields in order.
macro_rules! bin_struct {
    ($t:ty { $($field:ident),* $(,)? }) => {
        impl $crate::binio::Bin for $t {
            fn write(&self, w: &mut $crate::binio::Writer) {
                $( $crate::binio::Bin::write(&self.$field, w); )*
            }
            fn read(r: &mut $crate::binio::Reader<'_>) -> Option<Self> {
                Some(Self { $( $field: $crate::binio::Bin::read(r)?, )* })
            }
        }
    };
}
pub(crate) use bin_struct;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_truncation() {
        let value: (Vec<Vec3>, Option<String>) =
            (vec![Vec3::X, Vec3::NEG_Y], Some("é".to_string()));
        let mut w = Writer::default();
        value.0.write(&mut w);
        value.1.write(&mut w);
        let mut r = Reader::new(&w.bytes);
        assert_eq!(Vec::<Vec3>::read(&mut r), Some(value.0));
        assert_eq!(Option::<String>::read(&mut r), Some(value.1));
        assert!(r.is_empty());
        for cut in 0..w.bytes.len() {
            let mut r = Reader::new(&w.bytes[..cut]);
            let whole = Vec::<Vec3>::read(&mut r).and_then(|_| Option::<String>::read(&mut r));
            assert_eq!(whole, None, "cut at {cut}");
        }
        let mut huge = Writer::default();
        u64::MAX.write(&mut huge);
        assert_eq!(Vec::<u8>::read(&mut Reader::new(&huge.bytes)), None);
    }
}
