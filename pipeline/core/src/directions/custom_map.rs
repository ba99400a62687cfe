//! The custom map of 004 §5.5 and §6.3: a route as the list of instructions sent once to the
//! navigator, one entry `(D, [T,] [E…,] M)` per leg.
//!
//! - `D`, the descriptor that picks the target out of the view: `Obvious`, `Isol` or `*`;
//! - `T`, a trajectory (`Trajp` / `Trajn`);
//! - `E`, verification and recovery items: `(q,-)` "the object reached has QOC `q`: it is the
//!   right one", `(q,C,D)` "it has QOC `q`: adjust it to corner `C`, then seek `D`";
//! - `M`, the corner to adjust the target to for the next leg, or `-`.
//!
//! The rover's version is rotation invariant (no compass, no corners; seed digest B.8): `Isol/n`
//! names the scene size ("most isolated of you and your `n − 1` nearest"), a recovery item
//! `(q,D)` has no corner ("you are at the landmark whose signature is `q`: from there seek
//! `D`"), and `cell` as `M` says "drive on until the target is the nearest landmark", the
//! arrival test of 000 §VII-B. The grammar reads and prints both, so 004's own strings
//! round-trip unchanged.

use std::fmt;
use std::str::FromStr;
use thiserror::Error;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Descriptor {
    Obvious,
    /// `Isol`, or `Isol/n` with the scene's size.
    Isol(Option<usize>),
    /// `*`: any object.
    Any,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Trajectory {
    Trajp,
    Trajn,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Corner {
    SE,
    SW,
    NE,
    NW,
}

/// `M`: how to hold the target for the next leg.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Adjust {
    Corner(Corner),
    /// Drive on until the target is the nearest landmark (its Voronoi cell, 000 §VII-B).
    Cell,
    /// `-`: nothing (the last leg).
    Null,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Item {
    /// `(q,-)`: an object with QOC / signature `q` is the intended one.
    Verify { signature: u32 },
    /// `(q,C,D)` or `(q,D)`: an object with signature `q` is a known wrong one; adjust it to
    /// corner `C` (004) and seek `D` from there.
    Recover {
        signature: u32,
        corner: Option<Corner>,
        seek: Descriptor,
    },
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Entry {
    pub descriptor: Descriptor,
    pub trajectory: Option<Trajectory>,
    pub items: Vec<Item>,
    pub adjust: Adjust,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CustomMap {
    pub entries: Vec<Entry>,
}

impl fmt::Display for Descriptor {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Descriptor::Obvious => f.write_str("Obvious"),
            Descriptor::Isol(None) => f.write_str("Isol"),
            Descriptor::Isol(Some(n)) => write!(f, "Isol/{n}"),
            Descriptor::Any => f.write_str("*"),
        }
    }
}

impl fmt::Display for Corner {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(self, f)
    }
}

impl fmt::Display for Item {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Item::Verify { signature } => write!(f, "({signature},-)"),
            Item::Recover {
                signature,
                corner: Some(c),
                seek,
            } => write!(f, "({signature},{c},{seek})"),
            Item::Recover {
                signature,
                corner: None,
                seek,
            } => write!(f, "({signature},{seek})"),
        }
    }
}

impl fmt::Display for Entry {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "({}", self.descriptor)?;
        if let Some(t) = self.trajectory {
            write!(f, ",{t:?}")?;
        }
        for item in &self.items {
            write!(f, ",{item}")?;
        }
        match self.adjust {
            Adjust::Corner(c) => write!(f, ",{c})"),
            Adjust::Cell => f.write_str(",cell)"),
            Adjust::Null => f.write_str(",-)"),
        }
    }
}

impl fmt::Display for CustomMap {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let entries: Vec<String> = self.entries.iter().map(Entry::to_string).collect();
        write!(f, "({})", entries.join(", "))
    }
}

/// Why a custom map string does not parse.
#[derive(Debug, Error, PartialEq, Eq)]
pub enum CustomMapError {
    #[error("custom map {0}")]
    Syntax(String),
    #[error("entry {entry}: {reason}")]
    Entry { entry: usize, reason: String },
}

/// A parenthesized list or an atom.
#[derive(Debug)]
enum Node {
    Atom(String),
    List(Vec<Node>),
}

fn parse_nodes(text: &str) -> Result<Node, CustomMapError> {
    let mut stack: Vec<Vec<Node>> = vec![Vec::new()];
    let mut atom = String::new();
    let flush = |atom: &mut String, stack: &mut Vec<Vec<Node>>| {
        if !atom.is_empty() {
            stack
                .last_mut()
                .expect("the stack keeps its root")
                .push(Node::Atom(std::mem::take(atom)));
        }
    };
    for c in text.chars() {
        match c {
            '(' => {
                flush(&mut atom, &mut stack);
                stack.push(Vec::new());
            }
            ')' => {
                flush(&mut atom, &mut stack);
                if stack.len() < 2 {
                    return Err(CustomMapError::Syntax("has an unmatched ')'".into()));
                }
                let list = stack.pop().expect("checked");
                stack.last_mut().expect("checked").push(Node::List(list));
            }
            ',' | ' ' => flush(&mut atom, &mut stack),
            c => atom.push(c),
        }
    }
    flush(&mut atom, &mut stack);
    if stack.len() != 1 {
        return Err(CustomMapError::Syntax("has an unclosed '('".into()));
    }
    let mut root = stack.pop().expect("checked");
    match (root.len(), root.pop()) {
        (1, Some(node @ Node::List(_))) => Ok(node),
        _ => Err(CustomMapError::Syntax(
            "must be one parenthesized list of entries".into(),
        )),
    }
}

impl FromStr for Descriptor {
    type Err = String;
    fn from_str(s: &str) -> Result<Descriptor, String> {
        match s {
            "Obvious" => Ok(Descriptor::Obvious),
            "Isol" => Ok(Descriptor::Isol(None)),
            "*" => Ok(Descriptor::Any),
            _ => match s.strip_prefix("Isol/").map(str::parse::<usize>) {
                Some(Ok(n)) if n >= 2 => Ok(Descriptor::Isol(Some(n))),
                _ => Err(format!(
                    "{s:?} is no descriptor (Obvious, Isol, Isol/n with n ≥ 2, *)"
                )),
            },
        }
    }
}

impl FromStr for Corner {
    type Err = String;
    fn from_str(s: &str) -> Result<Corner, String> {
        match s {
            "SE" => Ok(Corner::SE),
            "SW" => Ok(Corner::SW),
            "NE" => Ok(Corner::NE),
            "NW" => Ok(Corner::NW),
            _ => Err(format!("{s:?} is no corner (SE, SW, NE, NW)")),
        }
    }
}

fn item(nodes: &[Node]) -> Result<Item, String> {
    let atoms: Vec<&str> = nodes
        .iter()
        .map(|n| match n {
            Node::Atom(a) => Ok(a.as_str()),
            Node::List(_) => Err("an item holds no lists".to_string()),
        })
        .collect::<Result<_, _>>()?;
    let signature = |s: &str| {
        s.parse::<u32>()
            .map_err(|_| format!("{s:?} is no QOC / signature count"))
    };
    match atoms[..] {
        [q, "-"] => Ok(Item::Verify {
            signature: signature(q)?,
        }),
        [q, seek] => Ok(Item::Recover {
            signature: signature(q)?,
            corner: None,
            seek: seek.parse()?,
        }),
        [q, corner, seek] => Ok(Item::Recover {
            signature: signature(q)?,
            corner: Some(corner.parse()?),
            seek: seek.parse()?,
        }),
        _ => Err(format!("an item has 2 or 3 parts, not {}", atoms.len())),
    }
}

fn entry(nodes: &[Node]) -> Result<Entry, String> {
    let (Some(Node::Atom(first)), Some(Node::Atom(last))) = (nodes.first(), nodes.last()) else {
        return Err("an entry starts with a descriptor and ends with M".into());
    };
    if nodes.len() < 2 {
        return Err("an entry has a descriptor and M at least".into());
    }
    let descriptor = first.parse()?;
    let adjust = match last.as_str() {
        "-" => Adjust::Null,
        "cell" => Adjust::Cell,
        c => Adjust::Corner(c.parse()?),
    };
    let mut middle = &nodes[1..nodes.len() - 1];
    let trajectory = match middle.first() {
        Some(Node::Atom(t)) if t == "Trajp" => Some(Trajectory::Trajp),
        Some(Node::Atom(t)) if t == "Trajn" => Some(Trajectory::Trajn),
        _ => None,
    };
    if trajectory.is_some() {
        middle = &middle[1..];
    }
    let items = middle
        .iter()
        .map(|n| match n {
            Node::List(parts) => item(parts),
            Node::Atom(a) => Err(format!("{a:?} in place of an item")),
        })
        .collect::<Result<_, _>>()?;
    Ok(Entry {
        descriptor,
        trajectory,
        items,
        adjust,
    })
}

impl FromStr for CustomMap {
    type Err = CustomMapError;
    fn from_str(text: &str) -> Result<CustomMap, CustomMapError> {
        let Node::List(entries) = parse_nodes(text)? else {
            unreachable!("parse_nodes returns a list");
        };
        let entries = entries
            .iter()
            .enumerate()
            .map(|(k, node)| match node {
                Node::List(parts) => entry(parts).map_err(|reason| CustomMapError::Entry {
                    entry: k + 1,
                    reason,
                }),
                Node::Atom(a) => Err(CustomMapError::Entry {
                    entry: k + 1,
                    reason: format!("{a:?} is not a parenthesized entry"),
                }),
            })
            .collect::<Result<_, _>>()?;
        Ok(CustomMap { entries })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 004 Fig. 14 and Fig. 28 (seed digest B.6).
    const GOLDEN: [&str; 2] = [
        "((Isol,SE), (Isol,NE), (Isol,NE), (Isol,Trajp,(2,NW,Isol),(1,-),-))",
        "((Isol,SE), (Isol,(4,NE,Isol),(3,-),SE), (Isol,SE), (Isol,(4,NE,Isol),(2,-),-))",
    ];

    #[test]
    fn the_papers_custom_maps_round_trip() {
        for text in GOLDEN {
            let map: CustomMap = text.parse().expect("004's own grammar");
            assert_eq!(map.to_string(), text);
        }
        let fig14: CustomMap = GOLDEN[0].parse().unwrap();
        assert_eq!(fig14.entries.len(), 4);
        assert_eq!(fig14.entries[3].trajectory, Some(Trajectory::Trajp));
        assert_eq!(
            fig14.entries[3].items,
            vec![
                Item::Recover {
                    signature: 2,
                    corner: Some(Corner::NW),
                    seek: Descriptor::Isol(None)
                },
                Item::Verify { signature: 1 }
            ]
        );
    }

    #[test]
    fn the_rotation_invariant_form_round_trips() {
        let text = "((Obvious,cell), (Isol/4,(3,-),(2,Obvious),cell), (Isol/3,-))";
        assert_eq!(text.parse::<CustomMap>().unwrap().to_string(), text);
    }

    #[test]
    fn malformed_maps_say_what_is_wrong() {
        for (text, needle) in [
            ("((Isol,SE)", "unclosed"),
            ("((Isol,SE)))", "unmatched"),
            ("(Isol,SE)", "entry 1"),
            ("((Isol,XX))", "no corner"),
            ("((Fuzzy,SE))", "no descriptor"),
            ("((Isol,(x,-),SE))", "signature"),
            ("((Isol/1,SE))", "no descriptor"),
            ("", "one parenthesized list"),
        ] {
            let error = text.parse::<CustomMap>().unwrap_err().to_string();
            assert!(error.contains(needle), "{text:?}: {error}");
        }
    }
}
