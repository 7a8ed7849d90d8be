//! Typed access to a block's properties: the last duplicate wins, wrong field types or
//! counts are located errors, and names nobody asked for become warnings.

use crate::error::{Diagnostics, Location, SceneError};
use crate::syntax::{Block, Prop, Value};
use glam::{DVec3, Vec3};
use std::path::Path;

/// Reads one block's properties and remembers which were used.
pub(crate) struct Props<'a> {
    block: &'a Block,
    file: &'a Path,
    used: Vec<bool>,
    /// The scene's origin: positions are stored relative to it.
    origin: DVec3,
}

impl<'a> Props<'a> {
    /// Starts reading `block` from `file`, positions relative to `origin`.
    pub(crate) fn new(block: &'a Block, file: &'a Path, origin: DVec3) -> Self {
        Self {
            block,
            file,
            used: vec![false; block.props.len()],
            origin,
        }
    }

    /// The file being read.
    pub(crate) fn file(&self) -> &'a Path {
        self.file
    }

    /// Where the block starts.
    pub(crate) fn block_at(&self) -> Location {
        Location::line(self.file, self.block.line)
    }

    /// Every property called `name`, in order, marked as used.
    pub(crate) fn all(&mut self, name: &str) -> Vec<&'a Prop> {
        let mut found = Vec::new();
        for (i, p) in self.block.props.iter().enumerate() {
            if p.name == name {
                self.used[i] = true;
                found.push(p);
            }
        }
        found
    }

    /// The last property called `name`, marking all of them used.
    pub(crate) fn last(&mut self, name: &str) -> Option<&'a Prop> {
        self.all(name).pop()
    }

    /// An error located at a property.
    pub(crate) fn error(&self, prop: &Prop, message: impl Into<String>) -> SceneError {
        SceneError::syntax(self.file, prop.line, message)
    }

    /// The property's fields as numbers, whatever their count.
    pub(crate) fn numbers(&self, prop: &Prop) -> Result<Vec<f32>, SceneError> {
        Ok(self.wide(prop)?.into_iter().map(|n| n as f32).collect())
    }

    /// The property's fields as the f64 numbers the file gives.
    fn wide(&self, prop: &Prop) -> Result<Vec<f64>, SceneError> {
        prop.values
            .iter()
            .map(|v| match v {
                Value::Num(n) => Ok(*n),
                other => Err(self.error(
                    prop,
                    format!(
                        "'{}' expects numbers, found {}",
                        prop.name,
                        other.describe()
                    ),
                )),
            })
            .collect()
    }

    /// The property's fields as exactly `n` numbers.
    pub(crate) fn exactly(&self, prop: &Prop, n: usize) -> Result<Vec<f32>, SceneError> {
        let nums = self.numbers(prop)?;
        if nums.len() != n {
            return Err(self.error(
                prop,
                format!("'{}' expects {n} numbers, found {}", prop.name, nums.len()),
            ));
        }
        Ok(nums)
    }

    /// The last `name` as one number.
    pub(crate) fn f32(&mut self, name: &str) -> Result<Option<f32>, SceneError> {
        match self.last(name) {
            Some(p) => Ok(Some(self.exactly(p, 1)?[0])),
            None => Ok(None),
        }
    }

    /// The last `name` as one number that must pass `valid`; otherwise an error at its line
    /// saying `expected`.
    pub(crate) fn f32_where(
        &mut self,
        name: &str,
        valid: impl Fn(f32) -> bool,
        expected: &str,
    ) -> Result<Option<f32>, SceneError> {
        let Some(p) = self.last(name) else {
            return Ok(None);
        };
        let v = self.exactly(p, 1)?[0];
        if valid(v) {
            Ok(Some(v))
        } else {
            Err(self.error(p, format!("'{name}' must be {expected}, found {v}")))
        }
    }

    /// The point given by three numbers of `prop` from `first` on, relative
    /// to the origin: subtracted in f64, so a position far from zero keeps
    /// its precision near the origin (docs/stability.md).
    pub(crate) fn point_at(&self, prop: &Prop, first: usize) -> Result<Vec3, SceneError> {
        let v = self.wide(prop)?;
        let p = DVec3::new(v[first], v[first + 1], v[first + 2]);
        Ok((p - self.origin).as_vec3())
    }

    /// The last `name` as a point relative to the origin, or the world point
    /// `default` (relative to the origin too) when it is not given.
    pub(crate) fn point_or(&mut self, name: &str, default: DVec3) -> Result<Vec3, SceneError> {
        Ok(self
            .point(name)?
            .unwrap_or_else(|| (default - self.origin).as_vec3()))
    }

    /// The last `name` as a point (three numbers) relative to the origin.
    pub(crate) fn point(&mut self, name: &str) -> Result<Option<Vec3>, SceneError> {
        match self.last(name) {
            Some(p) => {
                self.exactly(p, 3)?;
                Ok(Some(self.point_at(p, 0)?))
            }
            None => Ok(None),
        }
    }

    /// The last `name` as a colour: three numbers, none negative (a negative
    /// channel would subtract light).
    pub(crate) fn colour(&mut self, name: &str) -> Result<Option<Vec3>, SceneError> {
        let Some(p) = self.last(name) else {
            return Ok(None);
        };
        let v = Vec3::from_slice(&self.exactly(p, 3)?);
        if v.min_element() < 0.0 {
            return Err(self.error(
                p,
                format!(
                    "'{name}' channels must not be negative (a light or surface cannot take light away), found {} {} {}",
                    v.x, v.y, v.z
                ),
            ));
        }
        Ok(Some(v))
    }

    /// The last `name` as a non-zero direction, normalised.
    pub(crate) fn direction(&mut self, name: &str) -> Result<Option<Vec3>, SceneError> {
        let Some(p) = self.last(name) else {
            return Ok(None);
        };
        let v = Vec3::from_slice(&self.exactly(p, 3)?);
        normalize_wide(v)
            .map(Some)
            .ok_or_else(|| self.error(p, format!("'{name}' must not be a zero vector")))
    }

    /// The last `name` as one quoted string or bare word.
    pub(crate) fn text(&mut self, name: &str) -> Result<Option<(String, usize)>, SceneError> {
        let Some(p) = self.last(name) else {
            return Ok(None);
        };
        match p.values.as_slice() {
            [Value::Str(s) | Value::Word(s)] => Ok(Some((s.clone(), p.line))),
            _ => Err(self.error(p, format!("'{name}' expects one name or quoted string"))),
        }
    }

    /// Warns about every property no one read.
    pub(crate) fn finish(self, diag: &mut Diagnostics) {
        for (p, used) in self.block.props.iter().zip(self.used) {
            if !used {
                diag.warn(
                    Location::line(self.file, p.line),
                    format!(
                        "unknown property '{}' in '{}'; skipped",
                        p.name, self.block.kind
                    ),
                );
            }
        }
    }
}

/// `v` normalised, computed in f64 so components near `f32::MAX` do not
/// overflow the length; `None` only for the zero vector.
pub(crate) fn normalize_wide(v: Vec3) -> Option<Vec3> {
    v.as_dvec3().try_normalize().map(|n| n.as_vec3())
}
