//! The committed table files under `tables/` (format documented in `tables/README.md`).
//!
//! Both are line-oriented text: `#` starts a comment line; `# calculus NAME` and
//! `# relations N` are required header lines. A unary file has one row per relation:
//! `r LEFT(r) RIGHT(r) INVERSE(r)` with sets written `{a,b}`. A composition file has one row per
//! possible triple: `F ab_c bc_d ab_d w…` (feasible, with a witness configuration) or
//! `U ab_c bc_d ab_d` (undecided by the generator, so kept as possible).

use super::relation_set::RelationSet;
use std::fmt::Write as _;

/// Why a table file could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("table file line {line}: {reason}")]
pub struct TableFormatError {
    pub line: usize,
    pub reason: String,
}

fn err(line: usize, reason: impl Into<String>) -> TableFormatError {
    TableFormatError {
        line,
        reason: reason.into(),
    }
}

/// Header fields shared by both files: the `# calculus` and `# relations` comments before the
/// first data line, each exactly once.
fn read_header(text: &str) -> Result<(String, u8), TableFormatError> {
    let mut calculus = None;
    let mut relations = None;
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if !line.is_empty() && !line.starts_with('#') {
            break;
        }
        let Some(rest) = line.strip_prefix("# ") else {
            continue;
        };
        if let Some(name) = rest.strip_prefix("calculus ") {
            if calculus.replace(name.trim().to_string()).is_some() {
                return Err(err(i + 1, "'# calculus' given twice"));
            }
        } else if let Some(n) = rest.strip_prefix("relations ") {
            let n: u8 = n
                .trim()
                .parse()
                .map_err(|_| err(i + 1, format!("bad relation count {n:?}")))?;
            if !(1..=32).contains(&n) {
                return Err(err(i + 1, "relation count must be 1..=32"));
            }
            if relations.replace(n).is_some() {
                return Err(err(i + 1, "'# relations' given twice"));
            }
        }
    }
    Ok((
        calculus.ok_or_else(|| err(0, "missing '# calculus NAME' header"))?,
        relations.ok_or_else(|| err(0, "missing '# relations N' header"))?,
    ))
}

fn data_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'))
}

fn relation(line: usize, word: &str, n: u8) -> Result<u8, TableFormatError> {
    let r: u8 = word
        .parse()
        .map_err(|_| err(line, format!("{word:?} is not a relation number")))?;
    if r == 0 || r > n {
        return Err(err(line, format!("relation {r} outside 1..={n}")));
    }
    Ok(r)
}

/// The unary operator table of one calculus.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnaryFile {
    pub calculus: String,
    pub relations: u8,
    pub left: Vec<RelationSet>,
    pub right: Vec<RelationSet>,
    pub inverse: Vec<RelationSet>,
}

impl UnaryFile {
    pub fn parse(text: &str) -> Result<UnaryFile, TableFormatError> {
        let (calculus, relations) = read_header(text)?;
        let n = relations as usize;
        let mut rows: Vec<Option<[RelationSet; 3]>> = vec![None; n];
        for (line, l) in data_lines(text) {
            let words: Vec<&str> = l.split_whitespace().collect();
            if words.len() != 4 {
                return Err(err(line, "expected 'r LEFT RIGHT INVERSE'"));
            }
            let r = relation(line, words[0], relations)?;
            let mut sets = [RelationSet::EMPTY; 3];
            for (k, w) in words[1..].iter().enumerate() {
                let s: RelationSet = w.parse().map_err(|e| err(line, format!("{e}")))?;
                if !s.is_subset(RelationSet::all(n)) {
                    return Err(err(line, format!("{s} names a relation above {n}")));
                }
                sets[k] = s;
            }
            if rows[r as usize - 1].replace(sets).is_some() {
                return Err(err(line, format!("relation {r} listed twice")));
            }
        }
        let mut file = UnaryFile {
            calculus,
            relations,
            left: Vec::with_capacity(n),
            right: Vec::with_capacity(n),
            inverse: Vec::with_capacity(n),
        };
        for (i, row) in rows.into_iter().enumerate() {
            let [l, r, inv] = row.ok_or_else(|| err(0, format!("relation {} missing", i + 1)))?;
            file.left.push(l);
            file.right.push(r);
            file.inverse.push(inv);
        }
        Ok(file)
    }

    /// Canonical text; `description` lines are written as comments after the header.
    pub fn to_text(&self, description: &[&str]) -> String {
        let mut s = String::new();
        writeln!(s, "# qrm unary operator table").unwrap();
        writeln!(s, "# calculus {}", self.calculus).unwrap();
        writeln!(s, "# relations {}", self.relations).unwrap();
        for d in description {
            writeln!(s, "# {d}").unwrap();
        }
        writeln!(
            s,
            "# columns: r  LEFT(AB:C=r)=BC:A  RIGHT(AB:C=r)=CA:B  INVERSE(AB:C=r)=BA:C"
        )
        .unwrap();
        for i in 0..self.relations as usize {
            writeln!(
                s,
                "{} {} {} {}",
                i + 1,
                self.left[i],
                self.right[i],
                self.inverse[i]
            )
            .unwrap();
        }
        s
    }
}

/// Whether a composition triple was proved possible or only not refuted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EntryKind {
    Feasible,
    Undecided,
}

/// One possible `(AB:C, BC:D, AB:D)` triple.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CompositionEntry {
    pub kind: EntryKind,
    pub ab_c: u8,
    pub bc_d: u8,
    pub ab_d: u8,
    /// Witness coordinates as written (decimal or exact `p/q`); empty when undecided.
    pub witness: Vec<String>,
}

/// A composition table: every possible triple, in increasing `(ab_c, bc_d, ab_d)` order.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CompositionFile {
    pub calculus: String,
    pub relations: u8,
    pub entries: Vec<CompositionEntry>,
}

impl CompositionFile {
    pub fn parse(text: &str) -> Result<CompositionFile, TableFormatError> {
        let (calculus, relations) = read_header(text)?;
        let mut entries = Vec::new();
        for (line, l) in data_lines(text) {
            let words: Vec<&str> = l.split_whitespace().collect();
            if words.len() < 4 {
                return Err(err(line, "expected 'F|U ab_c bc_d ab_d …'"));
            }
            let kind = match words[0] {
                "F" => EntryKind::Feasible,
                "U" => EntryKind::Undecided,
                k => return Err(err(line, format!("unknown entry kind {k:?}"))),
            };
            let witness: Vec<String> = words[4..].iter().map(|w| w.to_string()).collect();
            if (kind == EntryKind::Feasible) == witness.is_empty() {
                return Err(err(line, "F rows carry a witness, U rows none"));
            }
            let entry = CompositionEntry {
                kind,
                ab_c: relation(line, words[1], relations)?,
                bc_d: relation(line, words[2], relations)?,
                ab_d: relation(line, words[3], relations)?,
                witness,
            };
            if let Some(prev) = entries.last() {
                let key = |e: &CompositionEntry| (e.ab_c, e.bc_d, e.ab_d);
                if key(prev) >= key(&entry) {
                    return Err(err(line, "rows must be sorted and unique"));
                }
            }
            entries.push(entry);
        }
        Ok(CompositionFile {
            calculus,
            relations,
            entries,
        })
    }

    pub fn to_text(&self, description: &[&str]) -> String {
        let mut s = String::new();
        writeln!(s, "# qrm composition table: COMPOSE(AB:C, BC:D) -> AB:D").unwrap();
        writeln!(s, "# calculus {}", self.calculus).unwrap();
        writeln!(s, "# relations {}", self.relations).unwrap();
        for d in description {
            writeln!(s, "# {d}").unwrap();
        }
        writeln!(
            s,
            "# rows: F ab_c bc_d ab_d <witness>   (possible, witness configuration)"
        )
        .unwrap();
        writeln!(
            s,
            "#       U ab_c bc_d ab_d             (undecided, kept as possible)"
        )
        .unwrap();
        for e in &self.entries {
            match e.kind {
                EntryKind::Feasible => writeln!(
                    s,
                    "F {} {} {} {}",
                    e.ab_c,
                    e.bc_d,
                    e.ab_d,
                    e.witness.join(" ")
                )
                .unwrap(),
                EntryKind::Undecided => writeln!(s, "U {} {} {}", e.ab_c, e.bc_d, e.ab_d).unwrap(),
            }
        }
        s
    }

    pub fn undecided(&self) -> usize {
        self.entries
            .iter()
            .filter(|e| e.kind == EntryKind::Undecided)
            .count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn composition_round_trip_and_errors() {
        let file = CompositionFile {
            calculus: "X".into(),
            relations: 3,
            entries: vec![
                CompositionEntry {
                    kind: EntryKind::Feasible,
                    ab_c: 1,
                    bc_d: 1,
                    ab_d: 2,
                    witness: vec!["0.5".into(), "-1/3".into()],
                },
                CompositionEntry {
                    kind: EntryKind::Undecided,
                    ab_c: 2,
                    bc_d: 3,
                    ab_d: 1,
                    witness: vec![],
                },
            ],
        };
        let text = file.to_text(&["test"]);
        assert_eq!(CompositionFile::parse(&text).unwrap(), file);
        assert!(CompositionFile::parse("# calculus X\n# relations 3\nF 1 1 4 0\n").is_err());
        assert!(CompositionFile::parse("# calculus X\n# relations 3\nF 1 1 1\n").is_err());
        assert!(CompositionFile::parse("# calculus X\n# relations 3\nU 1 1 2\nU 1 1 1\n").is_err());
        assert!(CompositionFile::parse("# relations 3\n").is_err());
        assert!(CompositionFile::parse("# calculus X\n# relations 3\n# relations 4\n").is_err());
    }

    #[test]
    fn unary_round_trip_and_errors() {
        let file = UnaryFile {
            calculus: "X".into(),
            relations: 2,
            left: vec![RelationSet::single(2), RelationSet::from_relations([1, 2])],
            right: vec![RelationSet::single(1), RelationSet::single(2)],
            inverse: vec![RelationSet::single(2), RelationSet::single(1)],
        };
        assert_eq!(UnaryFile::parse(&file.to_text(&[])).unwrap(), file);
        assert!(UnaryFile::parse("# calculus X\n# relations 2\n1 {2} {1} {2}\n").is_err());
        assert!(
            UnaryFile::parse("# calculus X\n# relations 2\n1 {3} {1} {2}\n2 {1} {1} {1}\n")
                .is_err()
        );
    }
}
