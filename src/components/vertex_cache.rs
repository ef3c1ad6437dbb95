//! PLACEHOLDER (replaced by the scene branch's full version at merge).
use std::fmt;
use std::str::FromStr;

/// Policy.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CachePolicy {
    /// none
    None,
    /// fifo
    Fifo(u32),
    /// lru
    Lru(u32),
}
impl FromStr for CachePolicy {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        if s == "none" { return Ok(CachePolicy::None); }
        let (k, n) = s.split_once(':').ok_or("bad")?;
        let n: u32 = n.parse().map_err(|_| "bad")?;
        match k { "fifo" => Ok(CachePolicy::Fifo(n)), "lru" => Ok(CachePolicy::Lru(n)), _ => Err("bad".into()) }
    }
}
impl fmt::Display for CachePolicy {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self { CachePolicy::None => write!(f, "none"), CachePolicy::Fifo(n) => write!(f, "fifo:{n}"), CachePolicy::Lru(n) => write!(f, "lru:{n}") }
    }
}
impl serde::Serialize for CachePolicy {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> { s.serialize_str(&self.to_string()) }
}
impl<'de> serde::Deserialize<'de> for CachePolicy {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = String::deserialize(d)?; s.parse().map_err(serde::de::Error::custom)
    }
}
/// stats
#[derive(Debug, Clone, Copy, Default)]
pub struct CacheStats {
    /// i
    pub indices: u64,
    /// t
    pub triangles: u64,
    /// u
    pub unique_vertices: u64,
    /// tv
    pub transformed: u64,
}
