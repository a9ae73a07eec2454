//! The variables a run's callback captured, in a checkpoint: a closure such as
//! `|t| { if s.penetrating > worst { worst = s.penetrating } }` keeps `worst` in a shared cell
//! that the script reads after the run, so a resumed run puts back the values those cells held
//! at the checkpoint, and what the script computes from them (a maximum, a list plotted at the
//! end) comes out as in a run never interrupted. Plain data is restored (unit, bools, integers,
//! floats bit for bit, characters, strings, arrays, maps, blobs, nested); a captured value that
//! holds anything else (a simulation handle, say) is left as the script's setup made it.

use rhai::{Array, Blob, Dynamic, FnPtr, Map};

use crate::geometry::checkpoint::{Decoder, Encoder};
use crate::geometry::GeometryError;

/// Deepest nesting of arrays and maps restored.
const MAX_DEPTH: usize = 64;

/// Encodes `v` if it is plain data; `false` (nothing written) otherwise.
fn encode_value(v: &Dynamic, e: &mut Encoder, depth: usize) -> bool {
    let v = v.flatten_clone();
    if depth > MAX_DEPTH {
        return false;
    }
    if v.is_unit() {
        e.u8(1);
    } else if let Ok(b) = v.as_bool() {
        e.u8(2);
        e.bool(b);
    } else if let Ok(i) = v.as_int() {
        e.u8(3);
        e.u64(i as u64);
    } else if let Ok(f) = v.as_float() {
        e.u8(4);
        e.f64(f);
    } else if let Ok(c) = v.as_char() {
        e.u8(6);
        e.u32(c as u32);
    } else if v.is_string() {
        e.u8(5);
        e.str(&v.to_string());
    } else if v.is_blob() {
        let Ok(b) = v.as_blob_ref() else { return false };
        e.u8(9);
        e.bytes(&b);
    } else if let Some(a) = v.read_lock::<Array>() {
        let mut inner = Encoder::new();
        inner.usize(a.len());
        if !a.iter().all(|x| encode_value(x, &mut inner, depth + 1)) {
            return false;
        }
        e.u8(7);
        e.buf.extend_from_slice(&inner.buf);
    } else if let Some(m) = v.read_lock::<Map>() {
        let mut inner = Encoder::new();
        inner.usize(m.len());
        for (k, x) in m.iter() {
            inner.str(k);
            if !encode_value(x, &mut inner, depth + 1) {
                return false;
            }
        }
        e.u8(8);
        e.buf.extend_from_slice(&inner.buf);
    } else {
        return false;
    }
    true
}

fn decode_value(d: &mut Decoder, depth: usize) -> Result<Dynamic, GeometryError> {
    if depth > MAX_DEPTH {
        return Err(d.error("captured values nested too deep"));
    }
    Ok(match d.u8("captured value")? {
        1 => Dynamic::UNIT,
        2 => Dynamic::from_bool(d.bool("captured bool")?),
        3 => Dynamic::from_int(d.u64("captured int")? as rhai::INT),
        4 => Dynamic::from_float(d.f64("captured float")?),
        5 => d.str("captured string")?.into(),
        6 => {
            let c = d.u32("captured char")?;
            Dynamic::from_char(char::from_u32(c).ok_or_else(|| d.error("not a character"))?)
        }
        7 => {
            let n = d.len(1, "captured array")?;
            let a: Array = (0..n)
                .map(|_| decode_value(d, depth + 1))
                .collect::<Result<_, _>>()?;
            Dynamic::from_array(a)
        }
        8 => {
            let n = d.len(9, "captured map")?;
            let mut m = Map::new();
            for _ in 0..n {
                let k = d.str("captured key")?;
                m.insert(k.into(), decode_value(d, depth + 1)?);
            }
            Dynamic::from_map(m)
        }
        9 => Dynamic::from_blob(d.bytes("captured blob")?.to_vec() as Blob),
        t => return Err(d.error(format!("captured value of unknown type {t}"))),
    })
}

/// The values of the variables `f` captured (empty for a function without captures).
pub fn encode_captured(f: Option<&FnPtr>) -> Vec<u8> {
    let mut e = Encoder::new();
    let curry = f.map_or(&[][..], |f| f.curry());
    e.usize(curry.len());
    for v in curry {
        let mut one = Encoder::new();
        let plain = v.is_shared() && encode_value(v, &mut one, 0);
        e.bool(plain);
        if plain {
            e.bytes(&one.buf);
        }
    }
    e.buf
}

/// Puts the values [`encode_captured`] saved back into the variables `f` captured (the same
/// closure of the same script, run again).
pub fn restore_captured(f: Option<&FnPtr>, d: &mut Decoder) -> Result<(), GeometryError> {
    let n = d.usize("captured variables")?;
    let curry = f.map_or(&[][..], |f| f.curry());
    if n != curry.len() {
        return Err(d.error(format!(
            "the callback captured {n} variables, this one {}",
            curry.len()
        )));
    }
    for v in curry {
        if !d.bool("captured variable")? {
            continue;
        }
        let bytes = d.bytes("captured variable")?;
        let mut inner = Decoder::new(bytes, &d.file);
        let value = decode_value(&mut inner, 0)?;
        let mut cell = v.clone();
        if let Some(mut guard) = cell.write_lock::<Dynamic>() {
            *guard = value;
        };
    }
    Ok(())
}
