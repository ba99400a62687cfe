//! Sets of base relations as a compact bitset: the unit of every map entry (000 §VI-A stores
//! "a set of possible EDC regions" per relation; 20 bits for EDC, 15 for FDC).

use std::fmt;
use std::str::FromStr;

/// A set of base relations numbered 1..=32, bit `r - 1` set when relation `r` is possible.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Default, PartialOrd, Ord)]
pub struct RelationSet(u32);

impl RelationSet {
    pub const EMPTY: RelationSet = RelationSet(0);

    /// The set of all relations `1..=count`.
    pub const fn all(count: usize) -> RelationSet {
        if count >= 32 {
            RelationSet(u32::MAX)
        } else {
            RelationSet((1u32 << count) - 1)
        }
    }

    /// The raw bitset: bit `r - 1` set when relation `r` is possible. Used by the map's
    /// table-driven set operations (000 §III-C applied to whole sets at once).
    pub const fn bits(self) -> u32 {
        self.0
    }

    /// The set whose bit `r - 1` is set exactly for the members `r`; inverse of [`Self::bits`].
    pub const fn from_bits(bits: u32) -> RelationSet {
        RelationSet(bits)
    }

    /// The singleton `{r}`; `r` is 1-based as in the papers.
    pub const fn single(r: u8) -> RelationSet {
        RelationSet(1u32 << (r - 1))
    }

    pub fn from_relations<I: IntoIterator<Item = u8>>(relations: I) -> RelationSet {
        relations
            .into_iter()
            .fold(RelationSet::EMPTY, |s, r| s.with(r))
    }

    pub const fn contains(self, r: u8) -> bool {
        r >= 1 && r <= 32 && self.0 & (1u32 << (r - 1)) != 0
    }

    pub const fn with(self, r: u8) -> RelationSet {
        RelationSet(self.0 | (1u32 << (r - 1)))
    }

    pub const fn without(self, r: u8) -> RelationSet {
        RelationSet(self.0 & !(1u32 << (r - 1)))
    }

    pub const fn union(self, other: RelationSet) -> RelationSet {
        RelationSet(self.0 | other.0)
    }

    pub const fn intersection(self, other: RelationSet) -> RelationSet {
        RelationSet(self.0 & other.0)
    }

    pub const fn difference(self, other: RelationSet) -> RelationSet {
        RelationSet(self.0 & !other.0)
    }

    pub const fn is_subset(self, other: RelationSet) -> bool {
        self.0 & !other.0 == 0
    }

    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    pub const fn len(self) -> usize {
        self.0.count_ones() as usize
    }

    /// Members in increasing order.
    pub fn iter(self) -> impl Iterator<Item = u8> {
        let mut bits = self.0;
        std::iter::from_fn(move || {
            if bits == 0 {
                return None;
            }
            let r = bits.trailing_zeros() as u8 + 1;
            bits &= bits - 1;
            Some(r)
        })
    }
}

impl fmt::Display for RelationSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("{")?;
        for (i, r) in self.iter().enumerate() {
            if i > 0 {
                f.write_str(",")?;
            }
            write!(f, "{r}")?;
        }
        f.write_str("}")
    }
}

impl fmt::Debug for RelationSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
}

/// Why a text could not be read as a relation set.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("invalid relation set {text:?}: {reason}")]
pub struct ParseRelationSetError {
    pub text: String,
    pub reason: String,
}

impl FromStr for RelationSet {
    type Err = ParseRelationSetError;

    /// Reads `{1,5,11}`, `1,5,11` or `{}`; relations must lie in 1..=32.
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let error = |reason: String| ParseRelationSetError {
            text: text.to_string(),
            reason,
        };
        let inner = text.trim();
        let inner = inner
            .strip_prefix('{')
            .map(|s| {
                s.strip_suffix('}')
                    .ok_or_else(|| error("missing '}'".into()))
            })
            .transpose()?
            .unwrap_or(inner);
        let mut set = RelationSet::EMPTY;
        for part in inner.split(',').map(str::trim).filter(|p| !p.is_empty()) {
            let r: u8 = part
                .parse()
                .map_err(|_| error(format!("{part:?} is not a relation number")))?;
            if !(1..=32).contains(&r) {
                return Err(error(format!("relation {r} is outside 1..=32")));
            }
            set = set.with(r);
        }
        Ok(set)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_and_parse_round_trip() {
        let s = RelationSet::from_relations([11, 1, 5]);
        assert_eq!(s.to_string(), "{1,5,11}");
        assert_eq!("{1,5,11}".parse::<RelationSet>().unwrap(), s);
        assert_eq!(" 5, 1 ,11".parse::<RelationSet>().unwrap(), s);
        assert_eq!("{}".parse::<RelationSet>().unwrap(), RelationSet::EMPTY);
        assert!("{0}".parse::<RelationSet>().is_err());
        assert!("{1,x}".parse::<RelationSet>().is_err());
        assert!("{1,2".parse::<RelationSet>().is_err());
    }

    #[test]
    fn set_operations() {
        let a = RelationSet::from_relations([1, 2, 3]);
        let b = RelationSet::from_relations([3, 4]);
        assert_eq!(a.union(b), RelationSet::from_relations([1, 2, 3, 4]));
        assert_eq!(a.intersection(b), RelationSet::single(3));
        assert_eq!(a.difference(b), RelationSet::from_relations([1, 2]));
        assert!(RelationSet::single(3).is_subset(a));
        assert_eq!(RelationSet::all(20).len(), 20);
        assert_eq!(a.iter().collect::<Vec<_>>(), vec![1, 2, 3]);
    }
}
