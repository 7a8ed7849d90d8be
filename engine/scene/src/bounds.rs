//! Axis-aligned bounding boxes, for culling, camera framing and light radii.

use glam::{Mat4, Vec3};
use serde::{Deserialize, Serialize};

/// An axis-aligned box; `min > max` on any axis means empty.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Aabb {
    /// The smallest corner.
    pub min: Vec3,
    /// The largest corner.
    pub max: Vec3,
}

impl Aabb {
    /// The box that contains nothing; the identity for [`Aabb::union`].
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::splat(f32::MAX),
        max: Vec3::splat(f32::MIN),
    };

    /// The smallest box holding every point.
    pub fn from_points<'a>(points: impl IntoIterator<Item = &'a Vec3>) -> Self {
        points.into_iter().fold(Self::EMPTY, |b, &p| Aabb {
            min: b.min.min(p),
            max: b.max.max(p),
        })
    }

    /// Whether the box holds no point.
    pub fn is_empty(&self) -> bool {
        self.min.cmpgt(self.max).any()
    }

    /// The smallest box holding both.
    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// The centre (meaningless when empty).
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// The length of the diagonal, 0 when empty.
    pub fn diagonal(&self) -> f32 {
        if self.is_empty() {
            0.0
        } else {
            (self.max - self.min).length()
        }
    }

    /// The box around this one after a transform (the eight corners, transformed).
    pub fn transformed(&self, m: &Mat4) -> Aabb {
        if self.is_empty() {
            return *self;
        }
        let corners: Vec<Vec3> = (0..8)
            .map(|i| {
                let c = Vec3::new(
                    if i & 1 == 0 { self.min.x } else { self.max.x },
                    if i & 2 == 0 { self.min.y } else { self.max.y },
                    if i & 4 == 0 { self.min.z } else { self.max.z },
                );
                m.transform_point3(c)
            })
            .collect();
        Aabb::from_points(&corners)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn union_transform_and_empty() {
        let a = Aabb::from_points(&[Vec3::new(-1.0, 0.0, 2.0), Vec3::new(1.0, 4.0, 3.0)]);
        assert_eq!(a.min, Vec3::new(-1.0, 0.0, 2.0));
        assert_eq!(a.max, Vec3::new(1.0, 4.0, 3.0));
        assert!(Aabb::EMPTY.is_empty());
        assert_eq!(Aabb::EMPTY.union(&a), a);
        assert_eq!(Aabb::EMPTY.diagonal(), 0.0);
        let t = a.transformed(&Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0)));
        assert_eq!(t.min, Vec3::new(0.0, 2.0, 5.0));
        assert_eq!(t.max, Vec3::new(2.0, 6.0, 6.0));
    }
}
