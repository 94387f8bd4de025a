//! The one place that maps law names (`[[region]] law = "…"`) to cell laws.
//!
//! A law is registered once for both dimensions through [`LawFamily`], whose `build`
//! is generic over the dimension; the registry turns it into a 2D and a 3D constructor.
//! Built in: `vem` ([`porofrac_vem::VemLaw`]), `mdem` ([`porofrac_mdem::MdemLaw`]) and
//! `dem` (the elastic central-force law, [`porofrac_mdem::DemLaw`]). A user adds a law
//! with [`LawRegistry::register`] and runs scenes with it through
//! [`crate::Scene::load_with`] (the `user_law` example of this crate registers a P1 law of
//! its own and runs a scene with it).
//!
//! What a failed cell becomes is part of the registration ([`PostFailure`]): MDEM and
//! DEM cells switch to the compression-only central-force law (Nilsen et al. (2017) eqs.
//! 32–33), VEM cells keep their law.

use std::collections::BTreeMap;
use std::fmt;
use std::sync::Arc;

use porofrac_law::{CellLaw, Stiffness};

/// A family of cell laws, one per dimension, built from the material's stiffness
/// (already in plane-stress form where the scene asks for it).
pub trait LawFamily: Send + Sync + 'static {
    /// The law of a material with stiffness `stiffness`, or why it cannot be built.
    fn build<const D: usize>(
        &self,
        stiffness: &Stiffness<D>,
    ) -> Result<Box<dyn CellLaw<D>>, String>;
}

/// What a cell of a law becomes when it fails.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PostFailure {
    /// It keeps its law (failure is recorded and marked only).
    Keep,
    /// The compression-only central-force DEM law of its material (Nilsen et al. (2017)
    /// eqs. 32–33).
    CompressionOnlyDem,
}

type Build<const D: usize> =
    Arc<dyn Fn(&Stiffness<D>) -> Result<Box<dyn CellLaw<D>>, String> + Send + Sync>;

#[derive(Clone)]
struct Entry {
    two: Build<2>,
    three: Build<3>,
    post_failure: PostFailure,
}

/// Law names and their constructors (see the module docs).
#[derive(Clone)]
pub struct LawRegistry {
    entries: BTreeMap<String, Entry>,
}

impl fmt::Debug for LawRegistry {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_list().entries(self.entries.keys()).finish()
    }
}

struct Vem;
impl LawFamily for Vem {
    fn build<const D: usize>(&self, s: &Stiffness<D>) -> Result<Box<dyn CellLaw<D>>, String> {
        Ok(Box::new(porofrac_vem::VemLaw::new(s.clone())))
    }
}

struct Mdem;
impl LawFamily for Mdem {
    fn build<const D: usize>(&self, s: &Stiffness<D>) -> Result<Box<dyn CellLaw<D>>, String> {
        Ok(Box::new(
            porofrac_mdem::MdemLaw::new(s).map_err(|e| e.to_string())?,
        ))
    }
}

struct Dem;
impl LawFamily for Dem {
    fn build<const D: usize>(&self, s: &Stiffness<D>) -> Result<Box<dyn CellLaw<D>>, String> {
        Ok(Box::new(
            porofrac_mdem::DemLaw::new(s, porofrac_mdem::DemMode::Elastic)
                .map_err(|e| e.to_string())?,
        ))
    }
}

impl Default for LawRegistry {
    /// The built-in laws `vem`, `mdem` and `dem`.
    fn default() -> Self {
        let mut r = Self::empty();
        r.register("vem", Vem, PostFailure::Keep);
        r.register("mdem", Mdem, PostFailure::CompressionOnlyDem);
        r.register("dem", Dem, PostFailure::CompressionOnlyDem);
        r
    }
}

impl LawRegistry {
    /// A registry without any law.
    pub fn empty() -> Self {
        Self {
            entries: BTreeMap::new(),
        }
    }

    /// Register `family` under `name` (replacing a law of that name).
    pub fn register(
        &mut self,
        name: impl Into<String>,
        family: impl LawFamily,
        post_failure: PostFailure,
    ) -> &mut Self {
        let family = Arc::new(family);
        let f2 = Arc::clone(&family);
        let entry = Entry {
            two: Arc::new(move |s: &Stiffness<2>| f2.build::<2>(s)),
            three: Arc::new(move |s: &Stiffness<3>| family.build::<3>(s)),
            post_failure,
        };
        self.entries.insert(name.into(), entry);
        self
    }

    /// Whether a law of that name is registered.
    pub fn contains(&self, name: &str) -> bool {
        self.entries.contains_key(name)
    }

    /// The registered names, sorted.
    pub fn names(&self) -> Vec<&str> {
        self.entries.keys().map(String::as_str).collect()
    }

    /// What a failed cell of law `name` becomes (`None`: no such law).
    pub fn post_failure(&self, name: &str) -> Option<PostFailure> {
        self.entries.get(name).map(|e| e.post_failure)
    }

    /// Build law `name` in `D` dimensions for a material of stiffness `stiffness`.
    pub fn build<const D: usize>(
        &self,
        name: &str,
        stiffness: &Stiffness<D>,
    ) -> Result<Box<dyn CellLaw<D>>, String> {
        let entry = self
            .entries
            .get(name)
            .ok_or_else(|| format!("is not a known law (known: {})", self.names().join(", ")))?;
        // D is 2 or 3 (scenes are checked); the stiffness is re-typed through `Any`
        // because the registry stores one constructor per dimension.
        let any: &dyn std::any::Any = stiffness;
        let built: Box<dyn std::any::Any> = if let Some(s) = any.downcast_ref::<Stiffness<2>>() {
            Box::new((entry.two)(s)?)
        } else if let Some(s) = any.downcast_ref::<Stiffness<3>>() {
            Box::new((entry.three)(s)?)
        } else {
            return Err(format!("laws exist in 2D and 3D, not in {D}D"));
        };
        built
            .downcast::<Box<dyn CellLaw<D>>>()
            .map(|b| *b)
            .map_err(|_| format!("laws exist in 2D and 3D, not in {D}D"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn built_in_laws_build_in_both_dimensions() {
        let r = LawRegistry::default();
        assert_eq!(r.names(), ["dem", "mdem", "vem"]);
        let s2 = Stiffness::<2>::isotropic(1e9, 0.3).unwrap();
        let s3 = Stiffness::<3>::isotropic(1e9, 0.3).unwrap();
        for name in ["vem", "mdem", "dem"] {
            assert!(r.build::<2>(name, &s2).unwrap().supports(3));
            assert!(r.build::<3>(name, &s3).unwrap().supports(4));
        }
        let err = r.build::<2>("fem", &s2).err().unwrap();
        assert!(err.contains("known: dem, mdem, vem"), "{err}");
        assert_eq!(r.post_failure("vem"), Some(PostFailure::Keep));
        assert_eq!(
            r.post_failure("mdem"),
            Some(PostFailure::CompressionOnlyDem)
        );
    }
}
