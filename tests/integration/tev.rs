//! Streaming to tev (src/render/tev.rs, `render --display`): a small server that speaks tev's
//! TCP protocol, written here from the protocol's description, receives the image's creation
//! and one full update per progressive round; the last update is the output image, bit for bit.

use std::io::Read;
use std::net::TcpListener;
use std::path::Path;
use std::process::Command;

/// A packet as tev would parse it.
#[derive(Debug)]
enum Packet {
    Create {
        name: String,
        width: i32,
        height: i32,
        channels: Vec<String>,
    },
    Update {
        name: String,
        channels: Vec<String>,
        region: [i32; 4],
        values: Vec<f32>,
    },
}

/// Reads fields from a packet's body.
struct Fields<'a>(&'a [u8]);

impl Fields<'_> {
    fn take(&mut self, n: usize) -> &[u8] {
        let (a, b) = self.0.split_at(n);
        self.0 = b;
        a
    }
    fn u8(&mut self) -> u8 {
        self.take(1)[0]
    }
    fn i32(&mut self) -> i32 {
        i32::from_le_bytes(self.take(4).try_into().unwrap())
    }
    fn i64(&mut self) -> i64 {
        i64::from_le_bytes(self.take(8).try_into().unwrap())
    }
    fn string(&mut self) -> String {
        let end = self
            .0
            .iter()
            .position(|&b| b == 0)
            .expect("a terminated string");
        let s = String::from_utf8(self.take(end).to_vec()).unwrap();
        self.take(1);
        s
    }
}

/// Read one packet, or `None` at the end of the stream.
fn read_packet(stream: &mut impl Read) -> Option<Packet> {
    let mut len = [0u8; 4];
    stream.read_exact(&mut len).ok()?;
    let len = u32::from_le_bytes(len) as usize;
    let mut body = vec![0u8; len - 4];
    stream.read_exact(&mut body).unwrap();
    let mut f = Fields(&body);
    let packet = match f.u8() {
        4 => {
            assert_eq!(f.u8(), 1, "grab focus on creation");
            let name = f.string();
            let (width, height, n) = (f.i32(), f.i32(), f.i32());
            let channels = (0..n).map(|_| f.string()).collect();
            Packet::Create {
                name,
                width,
                height,
                channels,
            }
        }
        6 => {
            f.u8();
            let name = f.string();
            let n = f.i32() as usize;
            let channels: Vec<String> = (0..n).map(|_| f.string()).collect();
            let region = [f.i32(), f.i32(), f.i32(), f.i32()];
            let offsets: Vec<i64> = (0..n).map(|_| f.i64()).collect();
            let strides: Vec<i64> = (0..n).map(|_| f.i64()).collect();
            let data: Vec<f32> =
                f.0.chunks_exact(4)
                    .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
                    .collect();
            // The region's values, pixel by pixel, read by the offsets and strides.
            let pixels = (region[2] * region[3]) as usize;
            let mut values = Vec::new();
            for i in 0..pixels {
                for c in 0..n {
                    values.push(data[(offsets[c] + strides[c] * i as i64) as usize]);
                }
            }
            f.0 = &[];
            Packet::Update {
                name,
                channels,
                region,
                values,
            }
        }
        t => panic!("packet type {t}: rtis sends only 4 and 6"),
    };
    assert!(f.0.is_empty(), "bytes left over in a packet");
    Some(packet)
}

#[test]
fn render_streams_each_round_to_a_tev_server() {
    let d = std::env::temp_dir().join(format!("rtis-tev-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let cornell = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.ron");
    let scene = d.join("scene.ron");
    std::fs::write(
        &scene,
        format!("Scene(extends: {cornell:?}, shader: Path(max_depth: 3))\n"),
    )
    .unwrap();
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let port = listener.local_addr().unwrap().port();
    let server = std::thread::spawn(move || {
        let (mut stream, _) = listener.accept().unwrap();
        let mut packets = Vec::new();
        while let Some(p) = read_packet(&mut stream) {
            packets.push(p);
        }
        packets
    });
    // 200 x 150: two regions across, two down (128 + 72, 128 + 22).
    let out = d.join("streamed.exr");
    let run = crate::common::output_within(
        Command::new(env!("CARGO_BIN_EXE_rtis"))
            .arg("render")
            .arg(&scene)
            .args([
                "--width",
                "200",
                "--height",
                "150",
                "--spp",
                "4",
                "--display",
            ])
            .arg(format!("127.0.0.1:{port}"))
            .arg("-o")
            .arg(&out),
        300,
    );
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{err}");
    assert!(err.contains("streaming each round to tev"), "{err}");
    let packets = server.join().unwrap();
    let Packet::Create {
        name,
        width,
        height,
        channels,
    } = &packets[0]
    else {
        panic!("the first packet creates the image: {:?}", packets[0]);
    };
    assert_eq!((name.as_str(), *width, *height), ("streamed.exr", 200, 150));
    assert_eq!(channels, &["R", "G", "B"]);
    // Rounds of 1, 1 and 2 spp: three full updates of four regions each.
    assert_eq!(packets.len(), 1 + 3 * 4);
    let mut image = vec![0f32; 200 * 150 * 3];
    let mut covered = vec![0u32; 200 * 150];
    for p in &packets[packets.len() - 4..] {
        let Packet::Update {
            name,
            channels,
            region: [x0, y0, w, h],
            values,
        } = p
        else {
            panic!("an update: {p:?}");
        };
        assert_eq!((name.as_str(), channels.len()), ("streamed.exr", 3));
        assert!(*w <= 128 && *h <= 128);
        for y in 0..*h {
            for x in 0..*w {
                let at = ((y0 + y) * 200 + x0 + x) as usize;
                covered[at] += 1;
                let i = (y * w + x) as usize * 3;
                image[at * 3..at * 3 + 3].copy_from_slice(&values[i..i + 3]);
            }
        }
    }
    assert!(
        covered.iter().all(|&c| c == 1),
        "each pixel sent once per round"
    );
    let written = image::open(&out).unwrap().to_rgb32f();
    let want: Vec<u32> = written
        .pixels()
        .flat_map(|p| p.0.map(f32::to_bits))
        .collect();
    let got: Vec<u32> = image.iter().map(|v| v.to_bits()).collect();
    assert!(got == want, "the last round sent is the image written");
    std::fs::remove_dir_all(&d).unwrap();
}

/// No viewer at the address: a clear error before any rendering, non-zero exit, no output.
#[test]
fn an_unreachable_display_is_refused_before_rendering() {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let port = listener.local_addr().unwrap().port();
    drop(listener);
    let d = std::env::temp_dir().join(format!("rtis-tev-none-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let out = d.join("x.png");
    let run = crate::common::output_within(
        Command::new(env!("CARGO_BIN_EXE_rtis"))
            .args(["render", "--width", "8", "--display"])
            .arg(format!("127.0.0.1:{port}"))
            .arg("-o")
            .arg(&out),
        300,
    );
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{err}");
    assert!(err.contains("cannot reach a tev viewer"), "{err}");
    assert!(!out.exists());
    std::fs::remove_dir_all(&d).unwrap();
}
