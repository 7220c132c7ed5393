//! Named and anonymous attributes: a list of typed arrays, each on a domain.
//!
//! Anonymous attributes are what Blender creates for field outputs that must survive
//! geometry changes (a primitive's UV Map output, Capture Attribute, Distribute Points'
//! Rotation); they travel with the geometry like named ones but are never exported.

use std::sync::atomic::{AtomicU64, Ordering};

use super::types::{Array, DataType, Domain};

#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum AttrId {
    Named(String),
    /// A unique id and, for messages, the socket that made it.
    Anonymous(u64, String),
}

impl AttrId {
    pub fn named(s: &str) -> AttrId {
        AttrId::Named(s.to_string())
    }
    /// A fresh anonymous id.
    pub fn anonymous(label: &str) -> AttrId {
        static NEXT: AtomicU64 = AtomicU64::new(1);
        AttrId::Anonymous(NEXT.fetch_add(1, Ordering::Relaxed), label.to_string())
    }
    pub fn name(&self) -> Option<&str> {
        match self {
            AttrId::Named(s) => Some(s),
            AttrId::Anonymous(..) => None,
        }
    }
    pub fn is_anonymous(&self) -> bool {
        matches!(self, AttrId::Anonymous(..))
    }
    pub fn label(&self) -> String {
        match self {
            AttrId::Named(s) => s.clone(),
            AttrId::Anonymous(i, l) => format!("<anonymous {l} #{i}>"),
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct Attribute {
    pub id: AttrId,
    pub domain: Domain,
    pub data: Array,
}

impl Attribute {
    pub fn data_type(&self) -> DataType {
        self.data.data_type()
    }
}

/// A component's generic attributes, in creation order (as Blender lists them).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Attributes(pub Vec<Attribute>);

impl Attributes {
    pub fn get(&self, id: &AttrId) -> Option<&Attribute> {
        self.0.iter().find(|a| &a.id == id)
    }
    pub fn get_mut(&mut self, id: &AttrId) -> Option<&mut Attribute> {
        self.0.iter_mut().find(|a| &a.id == id)
    }
    pub fn named(&self, name: &str) -> Option<&Attribute> {
        self.0.iter().find(|a| a.id.name() == Some(name))
    }
    pub fn contains(&self, id: &AttrId) -> bool {
        self.get(id).is_some()
    }
    /// Adds or replaces an attribute.
    pub fn set(&mut self, id: AttrId, domain: Domain, data: Array) {
        if let Some(a) = self.get_mut(&id) {
            a.domain = domain;
            a.data = data;
        } else {
            self.0.push(Attribute { id, domain, data });
        }
    }
    pub fn remove(&mut self, id: &AttrId) -> Option<Attribute> {
        let i = self.0.iter().position(|a| &a.id == id)?;
        Some(self.0.remove(i))
    }
    pub fn iter(&self) -> impl Iterator<Item = &Attribute> {
        self.0.iter()
    }
    pub fn on(&self, domain: Domain) -> impl Iterator<Item = &Attribute> {
        self.0.iter().filter(move |a| a.domain == domain)
    }
    /// Keeps, on `domain`, the elements at `indices` (in that order).
    pub fn gather_domain(&mut self, domain: Domain, indices: &[usize]) {
        for a in self.0.iter_mut().filter(|a| a.domain == domain) {
            a.data = a.data.gather(indices);
        }
    }
    /// Appends `n` default values on `domain`.
    pub fn extend_domain_default(&mut self, domain: Domain, n: usize) {
        for a in self.0.iter_mut().filter(|a| a.domain == domain) {
            a.data.extend_default(n);
        }
    }
}
