//! Streaming images to the tev viewer (<https://github.com/Tom94/tev>) over its TCP protocol,
//! as pbrt-v4's `--display-server` does: `render --display HOST:PORT` shows each progressive
//! round as it completes.
//!
//! Every packet is a little-endian `u32` length (the whole packet's, this field included), a
//! `u8` type, then its fields; strings end with a zero byte. rtis sends two kinds (the numbers
//! of tev's `IpcPacket::EType`):
//! - `CreateImage` (4): grab focus (`u8`), image name, width, height and channel count
//!   (`i32` each), then the channel names (`R`, `G`, `B`).
//! - `UpdateImageV3` (6): grab focus, image name, channel count, channel names, the region's
//!   `x`, `y`, width and height (`i32`), one `i64` offset and one `i64` stride per channel,
//!   then the region's `f32` values: channel `c` of the region's pixel `i` (row-major) is value
//!   `offset[c] + stride[c] * i`. rtis interleaves R, G, B (offsets 0, 1, 2; strides 3) and
//!   sends regions of at most [`REGION`] x [`REGION`] pixels, as tev's own Python client does,
//!   so no packet is large.

use super::film::Image;
use std::io::Write;
use std::net::TcpStream;
use std::time::Duration;

/// How long a send may wait for the viewer to read before the viewer is given up.
pub const WRITE_TIMEOUT: Duration = Duration::from_secs(5);

/// Side of the square regions an update is cut into.
pub const REGION: u32 = 128;

/// tev's packet type for creating an image.
const CREATE_IMAGE: u8 = 4;
/// tev's packet type for updating a region of an image (its third version).
const UPDATE_IMAGE_V3: u8 = 6;
/// The channels rtis sends.
const CHANNELS: [&str; 3] = ["R", "G", "B"];

/// A packet under construction: its length is written by [`Packet::finish`].
struct Packet(Vec<u8>);

impl Packet {
    fn new(kind: u8) -> Self {
        let mut bytes = vec![0; 4];
        bytes.push(kind);
        Packet(bytes)
    }
    fn u8(&mut self, v: u8) -> &mut Self {
        self.0.push(v);
        self
    }
    fn i32(&mut self, v: i32) -> &mut Self {
        self.0.extend(v.to_le_bytes());
        self
    }
    fn i64(&mut self, v: i64) -> &mut Self {
        self.0.extend(v.to_le_bytes());
        self
    }
    fn string(&mut self, s: &str) -> &mut Self {
        self.0.extend(s.bytes().filter(|&b| b != 0));
        self.0.push(0);
        self
    }
    fn finish(&mut self) -> Vec<u8> {
        let len = self.0.len() as u32;
        self.0[..4].copy_from_slice(&len.to_le_bytes());
        std::mem::take(&mut self.0)
    }
}

/// The `CreateImage` packet of an RGB image `name` of `width` x `height`.
pub fn create_image(name: &str, width: u32, height: u32) -> Vec<u8> {
    let mut p = Packet::new(CREATE_IMAGE);
    p.u8(1)
        .string(name)
        .i32(width as i32)
        .i32(height as i32)
        .i32(CHANNELS.len() as i32);
    for c in CHANNELS {
        p.string(c);
    }
    p.finish()
}

/// The `UpdateImageV3` packets that send all of `image` as the image `name`, one per region.
pub fn update_image(name: &str, image: &Image) -> Vec<Vec<u8>> {
    let mut packets = Vec::new();
    for y0 in (0..image.height).step_by(REGION as usize) {
        for x0 in (0..image.width).step_by(REGION as usize) {
            let (w, h) = (REGION.min(image.width - x0), REGION.min(image.height - y0));
            let mut p = Packet::new(UPDATE_IMAGE_V3);
            p.u8(0).string(name).i32(CHANNELS.len() as i32);
            for c in CHANNELS {
                p.string(c);
            }
            p.i32(x0 as i32).i32(y0 as i32).i32(w as i32).i32(h as i32);
            for c in 0..CHANNELS.len() {
                p.i64(c as i64);
            }
            for _ in CHANNELS {
                p.i64(CHANNELS.len() as i64);
            }
            for y in y0..y0 + h {
                for x in x0..x0 + w {
                    for v in image.get(x, y).to_array() {
                        p.0.extend(v.to_le_bytes());
                    }
                }
            }
            packets.push(p.finish());
        }
    }
    packets
}

/// A connection to a tev viewer showing one image.
pub struct Display {
    stream: TcpStream,
    name: String,
}

impl Display {
    /// Connect to tev at `address` (`HOST:PORT`; tev listens on 127.0.0.1:14158 by default)
    /// and create the image `name` of `width` x `height` there.
    pub fn connect(address: &str, name: &str, width: u32, height: u32) -> Result<Self, String> {
        use std::net::ToSocketAddrs;
        let fail = |e: &dyn std::fmt::Display| {
            format!("--display {address}: cannot reach a tev viewer there: {e}")
        };
        // Every address the name has, in turn (`localhost` may give ::1 first, where tev
        // listens on 127.0.0.1).
        let mut last: Option<std::io::Error> = None;
        let mut stream = None;
        for addr in address.to_socket_addrs().map_err(|e| fail(&e))? {
            match TcpStream::connect_timeout(&addr, Duration::from_secs(5)) {
                Ok(s) => {
                    stream = Some(s);
                    break;
                }
                Err(e) => last = Some(e),
            }
        }
        let stream = stream.ok_or_else(|| match last {
            Some(e) => fail(&e),
            None => fail(&"the name resolves to no address"),
        })?;
        // A viewer that stops reading must not stall the render: a send that waits this long
        // fails, and the render goes on without the viewer.
        stream
            .set_write_timeout(Some(WRITE_TIMEOUT))
            .map_err(|e| fail(&e))?;
        let mut display = Display {
            stream,
            name: name.to_string(),
        };
        display
            .stream
            .write_all(&create_image(name, width, height))
            .map_err(|e| fail(&e))?;
        Ok(display)
    }

    /// Send the whole of `image` (same size as created).
    pub fn show(&mut self, image: &Image) -> std::io::Result<()> {
        for packet in update_image(&self.name, image) {
            self.stream.write_all(&packet)?;
        }
        self.stream.flush()
    }
}
