//! Stanford PLY meshes (ASCII, binary little- and big-endian), as Mitsuba 3 reads them: the
//! `vertex` element's `x, y, z`, its normals `nx, ny, nz` and texture coordinates (`u, v`,
//! `texture_u, texture_v` or `s, t`, not flipped) when it has them, and the `face` element's
//! `vertex_indices` (or `vertex_index`) lists, polygons split into fans of triangles. Other
//! elements and properties are read past.

use super::MeshData;
use glam::{DVec3, Vec2};
use std::path::Path;

/// Most vertices or faces a file may declare (a larger count is a corrupt header).
const MAX_COUNT: u64 = 1 << 31;

/// The encoding of the data after the header.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Format {
    Ascii,
    Little,
    Big,
}

/// A scalar type of the format.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
}

/// A property: a scalar, or a list with its count's type and its items' type.
#[derive(Clone, Debug)]
struct Property {
    name: String,
    kind: Kind,
}

#[derive(Clone, Copy, Debug)]
enum Kind {
    Scalar(Scalar),
    List(Scalar, Scalar),
}

#[derive(Clone, Debug)]
struct Element {
    name: String,
    count: u64,
    properties: Vec<Property>,
}

/// The data after the header, read value by value.
struct Data<'a> {
    bytes: &'a [u8],
    at: usize,
    format: Format,
    /// ASCII tokens, when the format is ASCII.
    tokens: std::str::SplitAsciiWhitespace<'a>,
}

impl Data<'_> {
    fn read(&mut self, s: Scalar) -> Result<f64, String> {
        if self.format == Format::Ascii {
            let t = self
                .tokens
                .next()
                .ok_or("the file ends before its data does (truncated)")?;
            return t
                .parse::<f64>()
                .map_err(|_| format!("`{t}` is not a number"));
        }
        let n = s.size();
        let b = self
            .bytes
            .get(self.at..self.at + n)
            .ok_or("the file ends before its data does (truncated)")?;
        self.at += n;
        let mut a = [0u8; 8];
        a[..n].copy_from_slice(b);
        if self.format == Format::Big {
            a[..n].reverse();
        }
        Ok(match s {
            Scalar::I8 => a[0] as i8 as f64,
            Scalar::U8 => a[0] as f64,
            Scalar::I16 => i16::from_le_bytes([a[0], a[1]]) as f64,
            Scalar::U16 => u16::from_le_bytes([a[0], a[1]]) as f64,
            Scalar::I32 => i32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::U32 => u32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::F32 => f32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Scalar::F64 => f64::from_le_bytes(a),
        })
    }
}

/// Read the PLY file at `path`.
pub fn load_ply(path: &Path) -> Result<MeshData, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read mesh file: {e}"))?;
    parse(&bytes)
}

/// The header's elements and format, and where the data starts.
fn header(bytes: &[u8]) -> Result<(Format, Vec<Element>, usize), String> {
    // The header is ASCII lines up to `end_header`.
    let end = bytes
        .windows(10)
        .position(|w| w == b"end_header")
        .ok_or("not a PLY file: no `end_header`")?;
    let mut data_start = end + 10;
    // The line break after `end_header` (LF or CRLF).
    if bytes.get(data_start) == Some(&b'\r') {
        data_start += 1;
    }
    if bytes.get(data_start) == Some(&b'\n') {
        data_start += 1;
    }
    let text = std::str::from_utf8(&bytes[..end]).map_err(|_| "the PLY header is not text")?;
    let mut lines = text.lines();
    if lines.next().map(str::trim) != Some("ply") {
        return Err("not a PLY file: it does not start with `ply`".into());
    }
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    for line in lines {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["format", f, _] => {
                format = Some(match *f {
                    "ascii" => Format::Ascii,
                    "binary_little_endian" => Format::Little,
                    "binary_big_endian" => Format::Big,
                    other => return Err(format!("unknown PLY format `{other}`")),
                })
            }
            ["comment", ..] | ["obj_info", ..] | [] => {}
            ["element", name, count] => {
                let count: u64 = count
                    .parse()
                    .map_err(|_| format!("element `{name}`: `{count}` is not a count"))?;
                if count > MAX_COUNT {
                    return Err(format!("element `{name}` declares {count} items: too many"));
                }
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    properties: Vec::new(),
                });
            }
            ["property", "list", count, item, name] => {
                let e = elements.last_mut().ok_or("a property before any element")?;
                let (c, i) = (Scalar::parse(count), Scalar::parse(item));
                let (Some(c), Some(i)) = (c, i) else {
                    return Err(format!("property `{name}`: unknown type in `{line}`"));
                };
                e.properties.push(Property {
                    name: name.to_string(),
                    kind: Kind::List(c, i),
                });
            }
            ["property", ty, name] => {
                let e = elements.last_mut().ok_or("a property before any element")?;
                let s = Scalar::parse(ty)
                    .ok_or_else(|| format!("property `{name}`: unknown type `{ty}`"))?;
                e.properties.push(Property {
                    name: name.to_string(),
                    kind: Kind::Scalar(s),
                });
            }
            _ => return Err(format!("unreadable PLY header line `{line}`")),
        }
    }
    let format = format.ok_or("the PLY header has no `format` line")?;
    Ok((format, elements, data_start))
}

/// The mesh of a PLY file's bytes.
pub fn parse(bytes: &[u8]) -> Result<MeshData, String> {
    let (format, elements, start) = header(bytes)?;
    let body = &bytes[start..];
    let ascii = if format == Format::Ascii {
        std::str::from_utf8(body).map_err(|_| "the ASCII data is not text")?
    } else {
        ""
    };
    let mut data = Data {
        bytes: body,
        at: 0,
        format,
        tokens: ascii.split_ascii_whitespace(),
    };
    let mut mesh = MeshData::default();
    let mut vertices = None;
    for e in &elements {
        let index = |name: &str| e.properties.iter().position(|p| p.name == name);
        let (x, y, z) = (index("x"), index("y"), index("z"));
        let normal = [index("nx"), index("ny"), index("nz")];
        let uv = [("u", "v"), ("texture_u", "texture_v"), ("s", "t")]
            .iter()
            .find_map(|(u, v)| Some((index(u)?, index(v)?)));
        let faces = index("vertex_indices").or_else(|| index("vertex_index"));
        let is_vertex = e.name == "vertex";
        let is_face = e.name == "face";
        if is_vertex && (x.is_none() || y.is_none() || z.is_none()) {
            return Err("the `vertex` element has no `x`, `y` and `z`".into());
        }
        if is_face && faces.is_none() {
            return Err("the `face` element has no `vertex_indices` list".into());
        }
        // An element of no properties holds no data, however many it counts.
        if e.properties.is_empty() {
            continue;
        }
        let mut values = vec![0.0f64; e.properties.len()];
        let mut list: Vec<f64> = Vec::new();
        for _ in 0..e.count {
            list.clear();
            for (k, p) in e.properties.iter().enumerate() {
                match p.kind {
                    Kind::Scalar(s) => values[k] = data.read(s)?,
                    Kind::List(c, item) => {
                        let n = data.read(c)?;
                        if !(0.0..=1024.0).contains(&n) {
                            return Err(format!("a `{}` list of {n} items", p.name));
                        }
                        let keep = is_face && Some(k) == faces;
                        for _ in 0..n as usize {
                            let v = data.read(item)?;
                            if keep {
                                list.push(v);
                            }
                        }
                    }
                }
            }
            if is_vertex {
                let at = |i: Option<usize>| i.map_or(0.0, |i| values[i]);
                let p = DVec3::new(at(x), at(y), at(z));
                if !p.is_finite() {
                    return Err(format!(
                        "vertex {} is not finite: {p}",
                        mesh.positions.len()
                    ));
                }
                mesh.positions.push(p);
                if normal.iter().all(Option::is_some) {
                    mesh.normals
                        .push(DVec3::new(at(normal[0]), at(normal[1]), at(normal[2])));
                }
                if let Some((u, v)) = uv {
                    mesh.uvs.push(Vec2::new(values[u] as f32, values[v] as f32));
                }
            }
            if is_face {
                // A polygon as a fan of triangles.
                for j in 1..list.len().saturating_sub(1) {
                    mesh.faces
                        .push([list[0], list[j], list[j + 1]].map(|i| i as u32));
                    let n = vertices.unwrap_or(mesh.positions.len()) as f64;
                    for i in [list[0], list[j], list[j + 1]] {
                        if i < 0.0 || i >= n || i.fract() != 0.0 {
                            return Err(format!(
                                "face {} refers to vertex {i}, but the file has {n} vertices",
                                mesh.faces.len() - 1
                            ));
                        }
                    }
                }
            }
        }
        if is_vertex {
            vertices = Some(mesh.positions.len());
        }
    }
    if vertices.is_none() {
        return Err("the PLY file has no `vertex` element".into());
    }
    if mesh.faces.is_empty() {
        return Err("the PLY file has no triangles".into());
    }
    // Normals that are not unit are normalised; a zero one drops them all (flat shading).
    if mesh
        .normals
        .iter()
        .any(|n| n.length_squared() == 0.0 || !n.is_finite())
    {
        mesh.normals.clear();
    } else {
        for n in &mut mesh.normals {
            *n = n.normalize();
        }
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad(format: &str, body: &[u8]) -> Vec<u8> {
        let mut b = format!(
            "ply\nformat {format} 1.0\ncomment a unit quad\nelement vertex 4\nproperty float x\n\
             property float y\nproperty float z\nproperty float u\nproperty float v\n\
             element face 1\nproperty list uchar int vertex_indices\nend_header\n"
        )
        .into_bytes();
        b.extend_from_slice(body);
        b
    }

    const XYZUV: [[f32; 5]; 4] = [
        [0.0, 0.0, 0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0, 1.0, 1.0],
        [0.0, 1.0, 0.0, 0.0, 1.0],
    ];

    fn binary(big: bool) -> Vec<u8> {
        let mut b = Vec::new();
        for v in XYZUV {
            for c in v {
                b.extend(if big {
                    c.to_be_bytes()
                } else {
                    c.to_le_bytes()
                });
            }
        }
        b.push(4);
        for i in [0i32, 1, 2, 3] {
            b.extend(if big {
                i.to_be_bytes()
            } else {
                i.to_le_bytes()
            });
        }
        b
    }

    /// The same quad in each encoding: four vertices with their coordinates, two triangles.
    #[test]
    fn each_format_reads_the_same_quad() {
        let ascii = "0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n4 0 1 2 3\n";
        for bytes in [
            quad("ascii", ascii.as_bytes()),
            quad("binary_little_endian", &binary(false)),
            quad("binary_big_endian", &binary(true)),
        ] {
            let m = parse(&bytes).unwrap();
            assert_eq!(m.positions.len(), 4);
            assert_eq!(m.positions[2], DVec3::new(1.0, 1.0, 0.0));
            assert_eq!(m.uvs[2], Vec2::new(1.0, 1.0));
            assert_eq!(m.faces, vec![[0, 1, 2], [0, 2, 3]]);
            assert!(m.normals.is_empty());
        }
    }

    /// A face index beyond the vertices, a truncated file and a header without `end_header`
    /// are errors that say so.
    #[test]
    fn bad_files_say_why() {
        let e = parse(&quad(
            "ascii",
            b"0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n3 0 1 9\n",
        ))
        .unwrap_err();
        assert!(e.contains("vertex 9") && e.contains("4 vertices"), "{e}");
        let e = parse(&quad("binary_little_endian", &binary(false)[..30])).unwrap_err();
        assert!(e.contains("truncated"), "{e}");
        let e = parse(b"ply\nformat ascii 1.0\n").unwrap_err();
        assert!(e.contains("end_header"), "{e}");
    }
}
