//! What a file format read with an object but prespline does not use (OBJ's `curv2`, `vp`,
//! `con`, techniques, …), kept with the scene object so that every save writes it back.
//!
//! Each format owns its kept type and implements [`Kept`] for it; a scene object holds any
//! number of them in [`Carried`], one per format at most, without this floor knowing any
//! format. The JSON scene stores each under its format's key (the `obj` field for OBJ).

use std::any::Any;
use std::fmt::Debug;

/// One format's kept data of one object.
pub trait Kept: Debug + Send + Sync + Any {
    /// The JSON scene field it is saved under (`"obj"`), also naming the format.
    fn key(&self) -> &'static str;
    /// The field's JSON value.
    fn to_json(&self) -> String;
    fn clone_box(&self) -> Box<dyn Kept>;
    /// Equal to another format's data of the same type.
    fn same(&self, other: &dyn Kept) -> bool;
    /// For the owning format to read its own type back.
    fn as_any(&self) -> &dyn Any;
    /// Checks references to other objects of the scene (`names` in scene order; `me` is
    /// this object's index), as one message without the object's name.
    fn check_scene(&self, _names: &SceneNames<'_>, _me: usize) -> Result<(), String> {
        Ok(())
    }
}

/// What [`Kept::check_scene`] may ask of the other objects.
pub struct SceneNames<'a> {
    pub objects: &'a [super::SceneObject],
}

impl SceneNames<'_> {
    /// The index of the object called `name`.
    #[must_use]
    pub fn find(&self, name: &str) -> Option<usize> {
        self.objects.iter().position(|o| o.name == name)
    }
}

/// The kept data of one object: at most one entry per format, in the order they were added.
#[derive(Debug, Default)]
pub struct Carried(Vec<Box<dyn Kept>>);

impl Carried {
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// The data of type `T` (the owning format's), if the object has it.
    #[must_use]
    pub fn get<T: Kept>(&self) -> Option<&T> {
        self.0.iter().find_map(|k| k.as_any().downcast_ref::<T>())
    }

    /// Adds or replaces the data of `k`'s format.
    pub fn set(&mut self, k: Box<dyn Kept>) {
        match self.0.iter_mut().find(|e| e.key() == k.key()) {
            Some(slot) => *slot = k,
            None => self.0.push(k),
        }
    }

    /// One format's data, under its JSON key.
    pub fn iter(&self) -> impl Iterator<Item = &dyn Kept> {
        self.0.iter().map(AsRef::as_ref)
    }

    /// `Carried` holding `k` alone.
    #[must_use]
    pub fn of(k: Box<dyn Kept>) -> Self {
        Self(vec![k])
    }
}

impl Clone for Carried {
    fn clone(&self) -> Self {
        Self(self.0.iter().map(|k| k.clone_box()).collect())
    }
}

impl PartialEq for Carried {
    fn eq(&self, other: &Self) -> bool {
        self.0.len() == other.0.len()
            && self.0.iter().all(|k| {
                other
                    .0
                    .iter()
                    .any(|o| o.key() == k.key() && k.same(o.as_ref()))
            })
    }
}

/// The boilerplate of [`Kept`] for a `Clone + PartialEq` type: `kept_boilerplate!()` inside
/// the impl writes `clone_box`, `same` and `as_any`.
#[macro_export]
macro_rules! kept_boilerplate {
    () => {
        fn clone_box(&self) -> Box<dyn $crate::scene::Kept> {
            Box::new(self.clone())
        }

        fn same(&self, other: &dyn $crate::scene::Kept) -> bool {
            other
                .as_any()
                .downcast_ref::<Self>()
                .is_some_and(|o| o == self)
        }

        fn as_any(&self) -> &dyn std::any::Any {
            self
        }
    };
}
