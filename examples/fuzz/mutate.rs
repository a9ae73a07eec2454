//! Mutations of seed inputs, drawn from a seeded SplitMix64 so that case `i` of seed `s` is
//! the same input on every run (the supervisor regenerates a case that killed its worker).
//!
//! Byte-level: flip a bit, set a byte, insert or delete a range, duplicate or copy a range,
//! insert a dictionary word, truncate, splice with another seed. Text-aware: replace a number
//! with an extreme one (0, -1, 1e308, NaN, 2⁶⁴, …), duplicate, delete or swap lines, repeat a
//! line or a fragment many times (deep nesting, huge counts). Binary-aware (images): change a
//! PNG chunk and fix its CRC, set a PNG/JPEG/BMP/PNM width or height to an extreme value.

use emilion::geometry::random::SplitMix64;

/// Largest input a mutation may build (bytes).
pub const MAX_INPUT: usize = 1 << 20;

/// Numbers that break parsers and the sizes derived from them.
const NUMBERS: &[&str] = &[
    "0",
    "-0",
    "1",
    "-1",
    "2",
    "3",
    "0.5",
    "-0.5",
    "1e-7",
    "0.0000001",
    "1e-300",
    "-1e-300",
    "1e9",
    "1e18",
    "1e300",
    "1e308",
    "-1e308",
    "1e309",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "Infinity",
    "65535",
    "65536",
    "2147483647",
    "2147483648",
    "4294967295",
    "4294967296",
    "9223372036854775807",
    "9223372036854775808",
    "18446744073709551615",
    "18446744073709551616",
    "99999999999999999999999",
    "1.7976931348623157e308",
    "5e-324",
    "1.",
    ".5",
    "-.5",
    "+1",
    "1e",
    "0x10",
    "",
];

/// The input for case `index` of `seed`: a seed input mutated 1 to ~16 times.
pub fn case(seed: u64, index: u64, seeds: &[Vec<u8>], dictionary: &[&str], text: bool) -> Vec<u8> {
    let mut rng = SplitMix64::new(seed ^ index.wrapping_mul(0xD1B5_4A32_D192_ED03));
    rng.next_u64();
    let mut data = if seeds.is_empty() {
        Vec::new()
    } else {
        seeds[rng.below(seeds.len())].clone()
    };
    // Some cases are the seeds themselves, so every seed keeps being read.
    if rng.below(64) == 0 {
        return data;
    }
    let rounds = 1 + rng.below(4) + if rng.bit() { rng.below(12) } else { 0 };
    for _ in 0..rounds {
        mutate_once(&mut rng, &mut data, seeds, dictionary, text);
        data.truncate(MAX_INPUT);
    }
    data
}

fn mutate_once(
    rng: &mut SplitMix64,
    data: &mut Vec<u8>,
    seeds: &[Vec<u8>],
    dictionary: &[&str],
    text: bool,
) {
    let structured = if text {
        rng.below(3) != 0
    } else {
        rng.below(3) == 0
    };
    if structured {
        let done = if text {
            text_mutation(rng, data, dictionary)
        } else {
            image_mutation(rng, data)
        };
        if done {
            return;
        }
    }
    byte_mutation(rng, data, seeds, dictionary);
}

fn byte_mutation(rng: &mut SplitMix64, data: &mut Vec<u8>, seeds: &[Vec<u8>], dict: &[&str]) {
    let n = data.len();
    match rng.below(10) {
        0 if n > 0 => {
            let i = rng.below(n);
            data[i] ^= 1 << rng.below(8);
        }
        1 if n > 0 => {
            let i = rng.below(n);
            data[i] = interesting_byte(rng);
        }
        2 => {
            let i = rng.below(n + 1);
            let k = 1 + rng.below(8);
            let bytes: Vec<u8> = (0..k).map(|_| interesting_byte(rng)).collect();
            data.splice(i..i, bytes);
        }
        3 if n > 0 => {
            let i = rng.below(n);
            let k = 1 + rng.below((n - i).min(64));
            data.drain(i..i + k);
        }
        4 if n > 0 => {
            // duplicate a range in place
            let i = rng.below(n);
            let k = 1 + rng.below((n - i).min(256));
            let chunk = data[i..i + k].to_vec();
            data.splice(i..i, chunk);
        }
        5 if n > 1 => {
            // copy a range over another place
            let (a, b) = (rng.below(n), rng.below(n));
            let k = 1 + rng.below((n - a).min(n - b).min(64));
            let chunk = data[a..a + k].to_vec();
            data[b..b + k].copy_from_slice(&chunk);
        }
        6 if !dict.is_empty() => {
            let i = rng.below(n + 1);
            let w = dict[rng.below(dict.len())].as_bytes().to_vec();
            data.splice(i..i, w);
        }
        7 if n > 0 => data.truncate(rng.below(n)),
        8 if !seeds.is_empty() => {
            // splice: the head of this input, the tail of another seed
            let other = &seeds[rng.below(seeds.len())];
            let cut = rng.below(n + 1);
            let from = rng.below(other.len() + 1);
            data.truncate(cut);
            data.extend_from_slice(&other[from..]);
        }
        _ => {
            let i = rng.below(n + 1);
            data.insert(i, rng.next_u64() as u8);
        }
    }
}

fn interesting_byte(rng: &mut SplitMix64) -> u8 {
    const B: &[u8] = &[
        0, 1, 0x7f, 0x80, 0xff, b'\n', b'\r', b' ', b'\t', b'-', b'.', b'e', b'0', b'9', b'{',
        b'}', b'<', b'>', b'/', b'"', b'[', b']', b',', b':',
    ];
    if rng.bit() {
        B[rng.below(B.len())]
    } else {
        rng.next_u64() as u8
    }
}

/// Spans of number-like tokens (digits with sign, dot, exponent) in `data`.
fn number_spans(data: &[u8]) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut i = 0;
    while i < data.len() {
        let c = data[i];
        if c.is_ascii_digit() || (c == b'-' && data.get(i + 1).is_some_and(u8::is_ascii_digit)) {
            let start = i;
            i += 1;
            while i < data.len()
                && (data[i].is_ascii_digit() || matches!(data[i], b'.' | b'e' | b'E' | b'-' | b'+'))
            {
                i += 1;
            }
            spans.push((start, i));
        } else {
            i += 1;
        }
    }
    spans
}

/// Line spans (with their newline).
fn line_spans(data: &[u8]) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut start = 0;
    for (i, &c) in data.iter().enumerate() {
        if c == b'\n' {
            spans.push((start, i + 1));
            start = i + 1;
        }
    }
    if start < data.len() {
        spans.push((start, data.len()));
    }
    spans
}

/// A count for repetitions: mostly small, sometimes thousands.
fn repeat_count(rng: &mut SplitMix64) -> usize {
    match rng.below(8) {
        0 => 1000 + rng.below(20_000),
        1 | 2 => 10 + rng.below(200),
        _ => 2 + rng.below(8),
    }
}

fn text_mutation(rng: &mut SplitMix64, data: &mut Vec<u8>, dict: &[&str]) -> bool {
    match rng.below(8) {
        0..=2 => {
            let spans = number_spans(data);
            if spans.is_empty() {
                return false;
            }
            let (a, b) = spans[rng.below(spans.len())];
            let new: Vec<u8> = if rng.below(4) == 0 {
                // a nearby value
                let v: f64 = std::str::from_utf8(&data[a..b])
                    .ok()
                    .and_then(|s| s.parse().ok())
                    .unwrap_or(1.0);
                let f = [0.0, -1.0, 0.5, 2.0, 10.0, 1e3, 1e-3][rng.below(7)];
                format!("{}", v * f).into_bytes()
            } else {
                NUMBERS[rng.below(NUMBERS.len())].as_bytes().to_vec()
            };
            data.splice(a..b, new);
            true
        }
        3 => {
            let lines = line_spans(data);
            if lines.is_empty() {
                return false;
            }
            let (a, b) = lines[rng.below(lines.len())];
            let line = data[a..b].to_vec();
            let k = repeat_count(rng).min(MAX_INPUT / line.len().max(1) + 1);
            let rep = line.repeat(k);
            data.splice(a..a, rep);
            true
        }
        4 => {
            let lines = line_spans(data);
            if lines.len() < 2 {
                return false;
            }
            let (a, b) = lines[rng.below(lines.len())];
            if rng.bit() {
                data.drain(a..b);
            } else {
                let (c, d) = lines[rng.below(lines.len())];
                let (l1, l2) = (data[a..b].to_vec(), data[c..d].to_vec());
                if a < c && b <= c {
                    data.splice(c..d, l1);
                    data.splice(a..b, l2);
                } else if c < a && d <= a {
                    data.splice(a..b, l2);
                    data.splice(c..d, l1);
                }
            }
            true
        }
        5 => {
            // repeat a random fragment many times (nesting, long tokens)
            if data.is_empty() {
                return false;
            }
            let a = rng.below(data.len());
            let k = 1 + rng.below((data.len() - a).min(24));
            let frag = data[a..a + k].to_vec();
            let times = repeat_count(rng).min(MAX_INPUT / 2 / frag.len() + 1);
            let rep = frag.repeat(times);
            data.splice(a..a, rep);
            true
        }
        6 if !dict.is_empty() => {
            // a dictionary word at a line start
            let lines = line_spans(data);
            let at = if lines.is_empty() {
                0
            } else {
                lines[rng.below(lines.len())].0
            };
            let w = dict[rng.below(dict.len())];
            let mut ins = w.as_bytes().to_vec();
            if rng.bit() {
                ins.extend_from_slice(NUMBERS[rng.below(NUMBERS.len())].as_bytes());
                ins.push(if rng.bit() { b'\n' } else { b' ' });
            }
            data.splice(at..at, ins);
            true
        }
        _ => {
            // a number token duplicated into a list (more numbers than expected)
            let spans = number_spans(data);
            if spans.is_empty() {
                return false;
            }
            let (a, b) = spans[rng.below(spans.len())];
            let mut tok = data[a..b].to_vec();
            tok.insert(0, if rng.bit() { b' ' } else { b',' });
            let k = 1 + rng.below(6);
            for _ in 0..k {
                data.splice(b..b, tok.clone());
            }
            true
        }
    }
}

/// Extreme image dimensions.
fn dimension(rng: &mut SplitMix64) -> u32 {
    const D: &[u32] = &[
        0,
        1,
        2,
        3,
        255,
        256,
        4096,
        16384,
        65535,
        65536,
        100_000,
        1 << 24,
        0x7fff_ffff,
        0xffff_ffff,
    ];
    D[rng.below(D.len())]
}

fn image_mutation(rng: &mut SplitMix64, data: &mut [u8]) -> bool {
    if data.starts_with(b"\x89PNG\r\n\x1a\n") {
        return png_mutation(rng, data);
    }
    if data.starts_with(b"\xff\xd8") {
        // JPEG: the first start-of-frame's height and width (big-endian u16)
        let sof = (0..data.len().saturating_sub(9))
            .find(|&i| data[i] == 0xff && matches!(data[i + 1], 0xc0..=0xc2));
        if let Some(i) = sof {
            let d = dimension(rng).min(65535) as u16;
            let at = i + 5 + 2 * rng.below(2);
            data[at..at + 2].copy_from_slice(&d.to_be_bytes());
            return true;
        }
        return false;
    }
    if data.starts_with(b"BM") && data.len() >= 26 {
        let d = dimension(rng) as i32;
        let d = if rng.bit() { d } else { d.wrapping_neg() };
        let at = 18 + 4 * rng.below(2);
        data[at..at + 4].copy_from_slice(&d.to_le_bytes());
        return true;
    }
    false
}

/// Changes one PNG chunk (its data, or the IHDR's width/height/depth/colour type) and writes
/// the right CRC back, so that the decoder goes past the checksum.
fn png_mutation(rng: &mut SplitMix64, data: &mut [u8]) -> bool {
    let mut chunks = Vec::new();
    let mut at = 8;
    while at + 12 <= data.len() {
        let len = u32::from_be_bytes([data[at], data[at + 1], data[at + 2], data[at + 3]]) as usize;
        if at + 12 + len > data.len() {
            break;
        }
        chunks.push((at, len));
        at += 12 + len;
    }
    if chunks.is_empty() {
        return false;
    }
    let (c, len) = chunks[rng.below(chunks.len())];
    let body = c + 8;
    if &data[c + 4..c + 8] == b"IHDR" && len >= 13 && rng.bit() {
        match rng.below(3) {
            0 => {
                let at = body + 4 * rng.below(2);
                data[at..at + 4].copy_from_slice(&dimension(rng).to_be_bytes());
            }
            1 => data[body + 8] = [0, 1, 2, 4, 8, 16, 32][rng.below(7)],
            _ => data[body + 9] = [0, 1, 2, 3, 4, 5, 6, 7][rng.below(8)],
        }
    } else if len > 0 {
        let i = body + rng.below(len);
        data[i] = rng.next_u64() as u8;
    } else {
        return false;
    }
    let crc = crc32(&data[c + 4..body + len]);
    data[body + len..body + len + 4].copy_from_slice(&crc.to_be_bytes());
    true
}

/// CRC-32 (IEEE), as PNG chunks use.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = 0xffff_ffffu32;
    for &b in bytes {
        crc ^= b as u32;
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xedb8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

#[cfg(test)]
mod tests {
    #[test]
    fn crc32_of_iend_is_the_png_constant() {
        assert_eq!(super::crc32(b"IEND"), 0xae42_6082);
    }
}
