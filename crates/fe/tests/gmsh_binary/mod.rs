//! ASCII → binary `.msh` 4.1 conversion for tests, little or big endian, following the format
//! description of the Gmsh manual (section 10.1): `$Entities`, `$Nodes` and `$Elements` become
//! binary (`int` 4 bytes, `size_t` 8, `double` 8), other sections are copied.

/// The binary twin of an ASCII `.msh` 4.1 text.
pub fn to_binary(ascii: &str, big_endian: bool) -> Vec<u8> {
    let mut out = Vec::new();
    let mut lines = ascii.lines();
    let int = |out: &mut Vec<u8>, t: &str| {
        let v: i32 = t.parse().unwrap();
        out.extend_from_slice(&if big_endian { v.to_be_bytes() } else { v.to_le_bytes() });
    };
    let size = |out: &mut Vec<u8>, t: &str| {
        let v: u64 = t.parse().unwrap();
        out.extend_from_slice(&if big_endian { v.to_be_bytes() } else { v.to_le_bytes() });
    };
    let double = |out: &mut Vec<u8>, t: &str| {
        let v: f64 = t.parse().unwrap();
        out.extend_from_slice(&if big_endian { v.to_be_bytes() } else { v.to_le_bytes() });
    };
    while let Some(line) = lines.next() {
        let section = line.trim();
        out.extend_from_slice(section.as_bytes());
        out.push(b'\n');
        let end = format!("$End{}", &section[1..]);
        let body: Vec<&str> = lines.by_ref().take_while(|l| l.trim() != end).collect();
        let mut tokens = body.iter().flat_map(|l| l.split_whitespace());
        let mut next = || tokens.next().unwrap();
        match section {
            "$MeshFormat" => {
                out.extend_from_slice(b"4.1 1 8\n");
                out.extend_from_slice(&if big_endian { 1i32.to_be_bytes() } else { 1i32.to_le_bytes() });
                out.push(b'\n');
            }
            "$Entities" => {
                let counts: Vec<usize> = (0..4).map(|_| next().parse().unwrap()).collect();
                for t in &counts {
                    size(&mut out, &t.to_string());
                }
                for (dim, &count) in counts.iter().enumerate() {
                    for _ in 0..count {
                        int(&mut out, next());
                        for _ in 0..if dim == 0 { 3 } else { 6 } {
                            double(&mut out, next());
                        }
                        let n: usize = next().parse().unwrap();
                        size(&mut out, &n.to_string());
                        for _ in 0..n {
                            int(&mut out, next());
                        }
                        if dim > 0 {
                            let n: usize = next().parse().unwrap();
                            size(&mut out, &n.to_string());
                            for _ in 0..n {
                                int(&mut out, next());
                            }
                        }
                    }
                }
                out.push(b'\n');
            }
            "$Nodes" => {
                let blocks: usize = next().parse().unwrap();
                size(&mut out, &blocks.to_string());
                for _ in 0..3 {
                    size(&mut out, next());
                }
                for _ in 0..blocks {
                    for _ in 0..3 {
                        int(&mut out, next());
                    }
                    let n: usize = next().parse().unwrap();
                    size(&mut out, &n.to_string());
                    for _ in 0..n {
                        size(&mut out, next());
                    }
                    for _ in 0..3 * n {
                        double(&mut out, next());
                    }
                }
                out.push(b'\n');
            }
            "$Elements" => {
                let blocks: usize = next().parse().unwrap();
                size(&mut out, &blocks.to_string());
                for _ in 0..3 {
                    size(&mut out, next());
                }
                for _ in 0..blocks {
                    let dim = next();
                    let entity = next();
                    let etype = next();
                    int(&mut out, dim);
                    int(&mut out, entity);
                    int(&mut out, etype);
                    let n: usize = next().parse().unwrap();
                    size(&mut out, &n.to_string());
                    for _ in 0..n {
                        let line_tokens = nodes_per_type(etype.parse().unwrap()) + 1;
                        for _ in 0..line_tokens {
                            size(&mut out, next());
                        }
                    }
                }
                out.push(b'\n');
            }
            _ => {
                for l in &body {
                    out.extend_from_slice(l.as_bytes());
                    out.push(b'\n');
                }
            }
        }
        out.extend_from_slice(end.as_bytes());
        out.push(b'\n');
    }
    out
}

fn nodes_per_type(t: i32) -> usize {
    match t {
        15 => 1,
        1 => 2,
        8 | 2 => 3,
        9 => 6,
        3 | 4 => 4,
        16 | 5 => 8,
        10 => 9,
        11 => 10,
        17 => 20,
        6 => 6,
        _ => panic!("element type {t}"),
    }
}
