//! Gmsh `.msh` 4.1 meshes, ASCII and binary.
//!
//! Volumes of tet4, tet10, hex8 and hex20 elements become solids (node order converted to
//! Abaqus's); every physical group becomes a node set (the nodes of its elements, whatever
//! their dimension) and physical volumes also become element sets, named by `$PhysicalNames`
//! (upper case) or `GROUP<dim>_<tag>` when unnamed. Gmsh files carry no material: give one
//! with [`Mesh::assign_material`].

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use super::{Mesh, MeshError, Origin, Solid};
use crate::element::SolidKind;

/// Read a `.msh` 4.1 file (ASCII or binary).
pub fn read(path: impl AsRef<Path>) -> Result<Mesh, MeshError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|source| MeshError::Io { file: path.into(), source })?;
    parse(&bytes, path)
}

/// Parse the bytes of a `.msh` 4.1 file; `path` names it in errors.
pub fn parse(bytes: &[u8], path: &Path) -> Result<Mesh, MeshError> {
    Reader { bytes, pos: 0, file: path.to_path_buf(), binary: false, swap: false }.run()
}

/// Gmsh element types: (number of nodes, solid kind if a supported volume element).
fn element_info(t: i32) -> Option<(usize, Option<SolidKind>)> {
    Some(match t {
        15 => (1, None),
        1 => (2, None),
        8 => (3, None),
        2 => (3, None),
        9 => (6, None),
        3 => (4, None),
        16 => (8, None),
        10 => (9, None),
        4 => (4, Some(SolidKind::Tet4)),
        11 => (10, Some(SolidKind::Tet10)),
        5 => (8, Some(SolidKind::Hex8)),
        17 => (20, Some(SolidKind::Hex20)),
        // Known but unsupported volumes: prisms, pyramids, hex27, high-order tets.
        6 => (6, None),
        7 => (5, None),
        12 => (27, None),
        13 => (18, None),
        14 => (14, None),
        18 => (15, None),
        19 => (13, None),
        29 => (20, None),
        _ => return None,
    })
}

/// Gmsh volume element types that stickslip cannot use.
fn unsupported_volume(t: i32) -> Option<&'static str> {
    Some(match t {
        6 => "prism (Gmsh type 6)",
        7 => "pyramid (Gmsh type 7)",
        12 => "hex27 (Gmsh type 12)",
        13 => "prism18 (Gmsh type 13)",
        14 => "pyramid14 (Gmsh type 14)",
        18 => "prism15 (Gmsh type 18)",
        19 => "pyramid13 (Gmsh type 19)",
        29 => "tet20 (Gmsh type 29)",
        _ => return None,
    })
}

/// Position of Abaqus node `i` in Gmsh's node list, per kind (mid-edge numbering differs).
pub(crate) fn abaqus_order(kind: SolidKind) -> &'static [usize] {
    match kind {
        SolidKind::Tet4 => &[0, 1, 2, 3],
        // Gmsh: 8 on edge (2,3), 9 on edge (1,3); Abaqus the other way round.
        SolidKind::Tet10 => &[0, 1, 2, 3, 4, 5, 6, 7, 9, 8],
        SolidKind::Hex8 => &[0, 1, 2, 3, 4, 5, 6, 7],
        // Gmsh edges: 8 (0,1) 9 (0,3) 10 (0,4) 11 (1,2) 12 (1,5) 13 (2,3) 14 (2,6) 15 (3,7)
        // 16 (4,5) 17 (4,7) 18 (5,6) 19 (6,7).
        SolidKind::Hex20 | SolidKind::Hex20R => &[0, 1, 2, 3, 4, 5, 6, 7, 8, 11, 13, 9, 16, 18, 19, 17, 10, 12, 14, 15],
    }
}

struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
    file: PathBuf,
    binary: bool,
    swap: bool,
}

impl Reader<'_> {
    fn at(&self) -> Origin {
        self.origin(self.pos)
    }

    /// The line of byte `pos`. Counting newlines is linear in the file: call it for errors only.
    fn origin(&self, pos: usize) -> Origin {
        let line = 1 + self.bytes[..pos.min(self.bytes.len())].iter().filter(|&&b| b == b'\n').count();
        Origin { file: self.file.clone(), line }
    }

    fn err(&self, msg: impl Into<String>) -> MeshError {
        MeshError::Syntax { at: self.at(), msg: msg.into() }
    }

    /// A count of items of at least `bytes_each` bytes (binary) or `tokens_each` numbers
    /// (ASCII, two bytes each at least: a digit and a separator), refused when the rest of the
    /// file cannot hold that many. Counts are used to reserve memory: an unchecked one from a
    /// damaged file would abort on a huge allocation.
    fn count(&mut self, what: &str, bytes_each: usize, tokens_each: usize) -> Result<usize, MeshError> {
        let start = self.mark();
        let n = self.size(what)?;
        let each = if self.binary { bytes_each } else { 2 * tokens_each };
        self.bounded(n, each, start, what)
    }

    /// Where the next value starts, for its error messages (ASCII values may follow white space
    /// and newlines; binary ones start right here).
    fn mark(&mut self) -> usize {
        if !self.binary {
            self.skip_space();
        }
        self.pos
    }

    /// `n` items of `each` bytes at least, refused (naming the line of `start`) when the rest
    /// of the file cannot hold them.
    fn bounded(&self, n: u64, each: usize, start: usize, what: &str) -> Result<usize, MeshError> {
        let left = self.bytes.len().saturating_sub(self.pos);
        match usize::try_from(n) {
            Ok(n) if n <= left / each.max(1) => Ok(n),
            _ => Err(MeshError::Syntax {
                at: self.origin(start),
                msg: format!("{what} {n} is more than the rest of the file ({left} bytes) can hold"),
            }),
        }
    }

    fn skip_space(&mut self) {
        while self.pos < self.bytes.len() && self.bytes[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
    }

    /// Next white-space separated ASCII token.
    fn token(&mut self) -> Result<&str, MeshError> {
        self.skip_space();
        let start = self.pos;
        while self.pos < self.bytes.len() && !self.bytes[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        if start == self.pos {
            return Err(self.err("unexpected end of file"));
        }
        std::str::from_utf8(&self.bytes[start..self.pos]).map_err(|_| self.err("expected ASCII text"))
    }

    fn ascii<T: std::str::FromStr>(&mut self, what: &str) -> Result<T, MeshError> {
        let t = self.token()?.to_string();
        t.parse().map_err(|_| self.err(format!("expected {what}, got {t:?}")))
    }

    fn raw<const N: usize>(&mut self) -> Result<[u8; N], MeshError> {
        let b: [u8; N] = self
            .bytes
            .get(self.pos..self.pos + N)
            .ok_or_else(|| self.err("unexpected end of binary data"))?
            .try_into()
            .unwrap();
        self.pos += N;
        Ok(if self.swap {
            let mut r = b;
            r.reverse();
            r
        } else {
            b
        })
    }

    /// A Gmsh `int`: 32 bits in binary files, and held to that range in ASCII ones (a tag of
    /// i64::MIN overflowed `abs`; a wider element type wrapped onto a supported one).
    fn int(&mut self, what: &str) -> Result<i64, MeshError> {
        if self.binary {
            Ok(i32::from_le_bytes(self.raw::<4>()?) as i64)
        } else {
            let start = self.mark();
            let v: i64 = self.ascii(what)?;
            if i32::try_from(v).is_err() {
                return Err(MeshError::Syntax {
                    at: self.origin(start),
                    msg: format!("{what} {v} is not a 32-bit integer"),
                });
            }
            Ok(v)
        }
    }

    fn size(&mut self, what: &str) -> Result<u64, MeshError> {
        if self.binary {
            Ok(u64::from_le_bytes(self.raw::<8>()?))
        } else {
            self.ascii(what)
        }
    }

    fn float(&mut self, what: &str) -> Result<f64, MeshError> {
        let start = self.mark();
        let x = if self.binary { f64::from_le_bytes(self.raw::<8>()?) } else { self.ascii(what)? };
        if !x.is_finite() {
            return Err(MeshError::Syntax {
                at: self.origin(start),
                msg: format!("{what} is {x}, expected a finite number"),
            });
        }
        Ok(x)
    }

    fn expect(&mut self, tag: &str) -> Result<(), MeshError> {
        let t = self.token()?;
        if t != tag {
            let t = t.to_string();
            return Err(self.err(format!("expected {tag}, got {t:?}")));
        }
        Ok(())
    }

    fn run(mut self) -> Result<Mesh, MeshError> {
        let mut names: HashMap<(i64, i64), String> = HashMap::new();
        // Physical tags of each entity (dim, tag).
        let mut entity_groups: HashMap<(i64, i64), Vec<i64>> = HashMap::new();
        let mut mesh = Mesh::default();
        let mut groups: BTreeMap<(i64, i64), (Vec<usize>, Vec<usize>)> = BTreeMap::new();
        let mut seen_format = false;
        loop {
            self.skip_space();
            if self.pos >= self.bytes.len() {
                break;
            }
            let section = self.token()?.to_string();
            // Binary data starts right after the section line's newline.
            if self.binary && self.bytes.get(self.pos) == Some(&b'\n') {
                self.pos += 1;
            }
            match section.as_str() {
                "$MeshFormat" => {
                    let version = self.token()?.to_string();
                    if version != "4.1" {
                        return Err(self.err(format!("Gmsh format {version} is not supported; save as version 4.1")));
                    }
                    let file_type: i64 = self.ascii("the file type")?;
                    let data_size: i64 = self.ascii("the data size")?;
                    if file_type == 1 {
                        if data_size != 8 {
                            return Err(self.err(format!("binary files need 8-byte sizes, got {data_size}")));
                        }
                        // One newline, then the integer 1 to detect the byte order.
                        self.pos += 1;
                        let one = self.raw::<4>()?;
                        self.swap = i32::from_le_bytes(one) != 1;
                        self.binary = true;
                    }
                    self.expect("$EndMeshFormat")?;
                    seen_format = true;
                }
                "$PhysicalNames" => {
                    // ASCII in binary files too: `dim tag name` per line.
                    self.skip_space();
                    let start = self.pos;
                    let n = self.ascii("the number of names")?;
                    let n = self.bounded(n, 6, start, "the number of names")?;
                    for _ in 0..n {
                        let dim: i64 = self.ascii("a dimension")?;
                        let tag: i64 = self.ascii("a physical tag")?;
                        self.skip_space();
                        let rest = &self.bytes[self.pos..];
                        let end = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
                        let name = String::from_utf8_lossy(&rest[..end]).trim().trim_matches('"').to_uppercase();
                        self.pos += end;
                        names.insert((dim, tag), name);
                    }
                    self.expect("$EndPhysicalNames")?;
                }
                "$Entities" => {
                    let counts =
                        [self.size("a count")?, self.size("a count")?, self.size("a count")?, self.size("a count")?];
                    for (dim, &count) in counts.iter().enumerate() {
                        for _ in 0..count {
                            let tag = self.int("an entity tag")?;
                            let n_coords = if dim == 0 { 3 } else { 6 };
                            for _ in 0..n_coords {
                                self.float("a coordinate")?;
                            }
                            let n_phys = self.count("a number of physical tags", 4, 1)?;
                            let mut phys = Vec::with_capacity(n_phys);
                            for _ in 0..n_phys {
                                phys.push(self.int("a physical tag")?.abs());
                            }
                            if dim > 0 {
                                let n_bound = self.count("a number of bounding entities", 4, 1)?;
                                for _ in 0..n_bound {
                                    self.int("a bounding entity")?;
                                }
                            }
                            entity_groups.insert((dim as i64, tag), phys);
                        }
                    }
                    self.expect("$EndEntities")?;
                }
                "$Nodes" => {
                    let blocks = self.size("the number of blocks")?;
                    let _n = self.size("the number of nodes")?;
                    self.size("the minimum node tag")?;
                    self.size("the maximum node tag")?;
                    for _ in 0..blocks {
                        self.int("an entity dimension")?;
                        self.int("an entity tag")?;
                        let parametric = self.int("the parametric flag")?;
                        if parametric != 0 {
                            return Err(self.err("parametric node coordinates are not supported"));
                        }
                        // A tag and three coordinates per node.
                        let n = self.count("a block size", 32, 4)?;
                        let mut tags = Vec::with_capacity(n);
                        for _ in 0..n {
                            tags.push(self.size("a node tag")?);
                        }
                        for tag in tags {
                            let xyz = [self.float("x")?, self.float("y")?, self.float("z")?];
                            mesh.add_node(tag, xyz).map_err(|node| MeshError::DuplicateNode { at: self.at(), node })?;
                        }
                    }
                    self.expect("$EndNodes")?;
                }
                "$Elements" => {
                    if !seen_format {
                        return Err(self.err("$Elements before $MeshFormat"));
                    }
                    let blocks = self.size("the number of blocks")?;
                    self.size("the number of elements")?;
                    self.size("the minimum element tag")?;
                    self.size("the maximum element tag")?;
                    let mut ids = std::collections::HashSet::new();
                    for _ in 0..blocks {
                        let dim = self.int("an entity dimension")?;
                        let entity = self.int("an entity tag")?;
                        let type_at = self.mark();
                        let etype = self.int("an element type")?;
                        // Checked before the block size, which depends on it; an ASCII type beyond
                        // i32 is refused, not wrapped onto a supported one.
                        let info = i32::try_from(etype).ok().and_then(element_info);
                        let Some((nn, kind)) = info else {
                            let at = self.origin(type_at);
                            return Err(MeshError::UnsupportedElement { at, kind: format!("Gmsh type {etype}") });
                        };
                        if let Some(name) = unsupported_volume(etype as i32) {
                            let at = self.origin(type_at);
                            return Err(MeshError::UnsupportedElement { at, kind: name.into() });
                        }
                        // A tag and `nn` node tags per element.
                        let n = self.count("a block size", 8 * (1 + nn), 1 + nn)?;
                        let phys = entity_groups.get(&(dim, entity)).cloned().unwrap_or_default();
                        let mut nodes = vec![0usize; nn];
                        for _ in 0..n {
                            let id = self.size("an element tag")?;
                            for slot in nodes.iter_mut() {
                                let tag = self.size("a node tag")?;
                                *slot = mesh.node(tag).ok_or_else(|| MeshError::UndefinedNode {
                                    at: self.at(),
                                    what: format!("element {id}"),
                                    node: tag,
                                })?;
                            }
                            for &p in &phys {
                                groups.entry((dim, p)).or_default().0.extend_from_slice(&nodes);
                            }
                            if let Some(kind) = kind {
                                if !ids.insert(id) {
                                    return Err(MeshError::DuplicateElement { at: self.at(), element: id });
                                }
                                let order = abaqus_order(kind);
                                let solid = Solid {
                                    id,
                                    kind,
                                    nodes: order.iter().map(|&g| nodes[g]).collect(),
                                    material: None,
                                };
                                for &p in &phys {
                                    groups.entry((dim, p)).or_default().1.push(mesh.solids.len());
                                }
                                mesh.solids.push(solid);
                            }
                        }
                    }
                    self.expect("$EndElements")?;
                }
                s if s.starts_with('$') => {
                    // Other sections ($NodeData, $Periodic, ...): skip to their end tag.
                    let end = format!("$End{}", &s[1..]);
                    let needle = end.as_bytes();
                    match self.bytes[self.pos..].windows(needle.len()).position(|w| w == needle) {
                        Some(p) => self.pos += p + needle.len(),
                        None => return Err(self.err(format!("{s} without {end}"))),
                    }
                }
                other => return Err(self.err(format!("expected a $Section, got {other:?}"))),
            }
        }
        if !seen_format {
            return Err(self.err("no $MeshFormat: not a Gmsh .msh file"));
        }
        for ((dim, tag), (nodes, solids)) in groups {
            let name = names.get(&(dim, tag)).cloned().unwrap_or_else(|| format!("GROUP{dim}_{tag}"));
            mesh.add_node_set(&name, nodes);
            if dim == 3 {
                mesh.element_sets.entry(name).or_default().extend(solids);
            }
        }
        Ok(mesh)
    }
}
