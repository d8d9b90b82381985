//! A ROS 2 message's CDR bytes decoded by the types of its definition: RustDDS's CDR
//! codec (`cdr-encoding`) reads the wire (alignment, byte order, lengths), driven field by
//! field through serde by the parsed definition.

use super::msgdef::{Elem, Leaf, Prim, Shape, Step, Types};
use serde::de::{DeserializeSeed, Deserializer, Error as _, SeqAccess, Visitor};
use std::fmt;

/// A decoded value.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Value {
    Float(f64),
    Int(i64),
    Uint(u64),
    Bool(bool),
    Text(String),
    /// A sequence or array of bytes (uint8, int8, char, byte, bool).
    Bytes(Vec<u8>),
    /// A message's fields in order, or the elements of an array or a sequence.
    List(Vec<Value>),
}

/// The encapsulation a ROS 2 message starts with: its 4 bytes, then the payload whose
/// alignment counts from 0.
const ENCAPSULATION_BYTES: usize = 4;

/// Decodes one serialized message (encapsulation header and payload) of `types`.
pub(crate) fn decode(types: &Types, bytes: &[u8]) -> Result<Value, String> {
    if bytes.len() < ENCAPSULATION_BYTES {
        return Err(format!("{} bytes: shorter than the 4-byte CDR encapsulation header", bytes.len()));
    }
    let payload = &bytes[ENCAPSULATION_BYTES..];
    let seed = MsgSeed { types, index: 0, budget: payload.len() };
    use cdr_encoding::CdrDeserializer;
    let decoded = match (bytes[0], bytes[1]) {
        (0, 1) => seed.deserialize(&mut CdrDeserializer::<byteorder::LittleEndian>::new(payload)),
        (0, 0) => seed.deserialize(&mut CdrDeserializer::<byteorder::BigEndian>::new(payload)),
        (a, b) => {
            return Err(format!(
                "encapsulation {a:#04x} {b:#04x}: plain CDR (0x00 0x01 little-endian, 0x00 0x00 big-endian) is read, not XCDR2"
            ));
        }
    };
    decoded.map_err(|e| format!("not a {} in CDR: {e}", types.types[0].name))
}

/// What a field path picks of a decoded message.
pub(crate) enum Picked<'v> {
    Value(&'v Value),
    /// An element of a byte sequence.
    Byte(u8),
}

/// The value at `steps` of a decoded message; None past the end of a sequence.
pub(crate) fn pick<'v>(value: &'v Value, steps: &[Step]) -> Option<Picked<'v>> {
    let mut v = value;
    for (k, s) in steps.iter().enumerate() {
        let (Step::Field(i) | Step::Index(i)) = *s;
        v = match v {
            Value::List(items) => items.get(i)?,
            Value::Bytes(b) if k + 1 == steps.len() => return b.get(i).map(|&b| Picked::Byte(b)),
            _ => return None,
        };
    }
    Some(Picked::Value(v))
}

/// A number of a leaf: the value of a numeric field, the seconds of a time, the yaw of
/// a quaternion (rad); None for text.
pub(crate) fn number(value: &Value, leaf: Leaf) -> Option<f64> {
    let scalar = |v: &Value| match v {
        Value::Float(x) => Some(*x),
        Value::Int(x) => Some(*x as f64),
        Value::Uint(x) => Some(*x as f64),
        Value::Bool(b) => Some(f64::from(u8::from(*b))),
        _ => None,
    };
    match leaf {
        Leaf::Number => scalar(value),
        Leaf::Text => None,
        Leaf::Time => match value {
            Value::List(f) if f.len() == 2 => {
                let (Value::Int(sec), Value::Uint(ns)) = (&f[0], &f[1]) else { return None };
                // whole nanoseconds are exact in an f64 below 2^53 ns (104 days): a time
                // written as decimal seconds with up to 9 digits comes back as its nearest f64
                let total = i128::from(*sec) * 1_000_000_000 + i128::from(*ns);
                Some(if total.unsigned_abs() < 1 << 53 { total as f64 / 1e9 } else { *sec as f64 + *ns as f64 / 1e9 })
            }
            _ => None,
        },
        Leaf::Yaw | Leaf::Roll | Leaf::Pitch => match value {
            Value::List(q) if q.len() == 4 => {
                let c: Vec<f64> = q.iter().filter_map(scalar).collect();
                let [x, y, z, w] = c[..] else { return None };
                // ZYX Euler angles of a unit quaternion: yaw about the frame's z axis,
                // then pitch, then roll
                Some(match leaf {
                    Leaf::Roll => (2.0 * (w * x + y * z)).atan2(1.0 - 2.0 * (x * x + y * y)),
                    Leaf::Pitch => (2.0 * (w * y - z * x)).clamp(-1.0, 1.0).asin(),
                    _ => (2.0 * (w * z + x * y)).atan2(1.0 - 2.0 * (y * y + z * z)),
                })
            }
            _ => None,
        },
    }
}

/// A message of `types.types[index]`; `budget` bounds a sequence's length by the bytes
/// of the message (each element takes one at least), so that a corrupted length is an
/// error, not a loop.
#[derive(Clone, Copy)]
pub(crate) struct MsgSeed<'t> {
    types: &'t Types,
    index: usize,
    budget: usize,
}

/// The longest message a live topic's sequences are bounded by (its length is not
/// known to the seed): a corrupted length is an error, not an allocation.
const MAX_LIVE_MESSAGE_BYTES: usize = 64 << 20;

impl<'t> MsgSeed<'t> {
    /// A message of the topic's type (`types`' first), of unknown length.
    pub(crate) fn new(types: &'t Types) -> Self {
        Self { types, index: 0, budget: MAX_LIVE_MESSAGE_BYTES }
    }
}

impl<'de> DeserializeSeed<'de> for MsgSeed<'_> {
    type Value = Value;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Value, D::Error> {
        let n = self.types.types[self.index].fields.len();
        d.deserialize_tuple(n, self)
    }
}

impl<'de> Visitor<'de> for MsgSeed<'_> {
    type Value = Value;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "a {}", self.types.types[self.index].name)
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Value, A::Error> {
        let ty = &self.types.types[self.index];
        let mut out = Vec::with_capacity(ty.fields.len());
        for f in &ty.fields {
            let seed = FieldSeed { types: self.types, elem: f.elem, shape: f.shape, budget: self.budget };
            out.push(seq.next_element_seed(seed)?.ok_or_else(|| A::Error::custom(format!("{} ends early", ty.name)))?);
        }
        Ok(Value::List(out))
    }
}

#[derive(Clone, Copy)]
struct FieldSeed<'t> {
    types: &'t Types,
    elem: Elem,
    shape: Shape,
    budget: usize,
}

impl<'de> DeserializeSeed<'de> for FieldSeed<'_> {
    type Value = Value;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Value, D::Error> {
        let one = FieldSeed { shape: Shape::One, ..self };
        match (self.shape, self.elem) {
            (Shape::One, Elem::Msg(index)) => MsgSeed { types: self.types, index, budget: self.budget }.deserialize(d),
            (Shape::One, Elem::Prim(p)) => prim(d, p),
            (Shape::Sequence, Elem::Prim(p)) if p.is_byte() => d.deserialize_byte_buf(BytesVisitor),
            (Shape::Sequence, _) => d.deserialize_seq(ListVisitor { one, len: None }),
            (Shape::Array(n), _) if n > self.budget => {
                Err(D::Error::custom(format!("an array of {n} in a message of {} bytes", self.budget)))
            }
            (Shape::Array(n), _) => d.deserialize_tuple(n, ListVisitor { one, len: Some(n) }),
        }
    }
}

fn prim<'de, D: Deserializer<'de>>(d: D, p: Prim) -> Result<Value, D::Error> {
    match p {
        Prim::Bool => d.deserialize_bool(PrimVisitor),
        Prim::I8 => d.deserialize_i8(PrimVisitor),
        Prim::U8 => d.deserialize_u8(PrimVisitor),
        Prim::I16 => d.deserialize_i16(PrimVisitor),
        Prim::U16 => d.deserialize_u16(PrimVisitor),
        Prim::I32 => d.deserialize_i32(PrimVisitor),
        Prim::U32 => d.deserialize_u32(PrimVisitor),
        Prim::I64 => d.deserialize_i64(PrimVisitor),
        Prim::U64 => d.deserialize_u64(PrimVisitor),
        Prim::F32 => d.deserialize_f32(PrimVisitor),
        Prim::F64 => d.deserialize_f64(PrimVisitor),
        Prim::Str => d.deserialize_string(PrimVisitor),
    }
}

struct PrimVisitor;

impl<'de> Visitor<'de> for PrimVisitor {
    type Value = Value;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a primitive value")
    }
    fn visit_bool<E>(self, v: bool) -> Result<Value, E> {
        Ok(Value::Bool(v))
    }
    fn visit_i64<E>(self, v: i64) -> Result<Value, E> {
        Ok(Value::Int(v))
    }
    fn visit_u64<E>(self, v: u64) -> Result<Value, E> {
        Ok(Value::Uint(v))
    }
    fn visit_f32<E>(self, v: f32) -> Result<Value, E> {
        Ok(Value::Float(f64::from(v)))
    }
    fn visit_f64<E>(self, v: f64) -> Result<Value, E> {
        Ok(Value::Float(v))
    }
    fn visit_str<E>(self, v: &str) -> Result<Value, E> {
        Ok(Value::Text(v.to_string()))
    }
}

struct BytesVisitor;

impl<'de> Visitor<'de> for BytesVisitor {
    type Value = Value;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a sequence of bytes")
    }
    fn visit_byte_buf<E>(self, v: Vec<u8>) -> Result<Value, E> {
        Ok(Value::Bytes(v))
    }
    fn visit_bytes<E>(self, v: &[u8]) -> Result<Value, E> {
        Ok(Value::Bytes(v.to_vec()))
    }
}

/// The elements of an array (`len`) or of a sequence (its length on the wire).
struct ListVisitor<'t> {
    one: FieldSeed<'t>,
    len: Option<usize>,
}

impl<'de> Visitor<'de> for ListVisitor<'_> {
    type Value = Value;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("an array or a sequence")
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Value, A::Error> {
        let mut out = Vec::with_capacity(self.len.unwrap_or(0));
        // every element takes a byte at least: a corrupted length ends at the message's end
        while let Some(v) = seq.next_element_seed(self.one)? {
            if out.len() == self.one.budget {
                return Err(A::Error::custom(format!(
                    "a sequence longer than its message's {} bytes",
                    self.one.budget
                )));
            }
            out.push(v);
        }
        if self.len.is_some_and(|n| n != out.len()) {
            return Err(A::Error::custom("an array ends early"));
        }
        Ok(Value::List(out))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn types(definition: &str) -> Types {
        Types::parse("t/msg/T", Some(definition), &crate::log::ros2::standard::definition).unwrap()
    }

    /// Bytes laid out by hand from the CDR rules (OMG DDS-XTypes 7.4.3, XCDR1): a
    /// header's stamp, its frame id (length with the NUL, then the bytes), one byte of
    /// padding so that the float64 starts at a multiple of 8 of the payload.
    #[test]
    fn a_message_is_decoded_by_its_definition() {
        let t = types("std_msgs/Header header\nfloat64 range\nuint8[] raw\n");
        let mut bytes = vec![0, 1, 0, 0]; // CDR, little-endian
        bytes.extend([1, 0, 0, 0, 2, 0, 0, 0]); // sec 1, nanosec 2
        bytes.extend([3, 0, 0, 0, b'a', b'b', 0]); // "ab"
        bytes.push(0); // padding to 16
        bytes.extend(1.5f64.to_le_bytes());
        bytes.extend([2, 0, 0, 0, 7, 9]); // raw = [7, 9]
        let v = decode(&t, &bytes).unwrap();
        let at = |path: &str| {
            let (steps, leaf) = t.path(path).unwrap();
            match pick(&v, &steps).unwrap() {
                Picked::Value(Value::Text(s)) => s.clone(),
                Picked::Value(x) => number(x, leaf).unwrap().to_string(),
                Picked::Byte(b) => b.to_string(),
            }
        };
        assert_eq!(at("header.stamp"), "1.000000002");
        assert_eq!(at("header.frame_id"), "ab");
        assert_eq!(at("range"), "1.5");
        assert_eq!(at("raw[1]"), "9");
        // cut short, or a sequence longer than the message: an error, not a panic or a loop
        assert!(decode(&t, &bytes[..bytes.len() - 3]).is_err());
        let mut long = bytes.clone();
        long[28..32].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(decode(&t, &long).is_err());
        // XCDR2 is refused by name
        assert!(decode(&t, &[0, 7, 0, 0]).unwrap_err().contains("XCDR2"));
    }

    /// The yaw of a quaternion about z by theta is theta (in (-pi, pi]); roll, pitch and
    /// yaw come back from nalgebra's quaternion of those ZYX Euler angles.
    #[test]
    fn a_quaternion_gives_its_euler_angles() {
        for theta in [-3.0, -1.0, 0.0, 0.5, 2.9] {
            let (s, c) = (theta / 2.0f64).sin_cos();
            let q = Value::List(vec![Value::Float(0.0), Value::Float(0.0), Value::Float(s), Value::Float(c)]);
            assert!((number(&q, Leaf::Yaw).unwrap() - theta).abs() < 1e-12, "{theta}");
        }
        for (roll, pitch, yaw) in [(0.3, -0.2, 2.5), (-1.0, 1.2, -0.7), (0.01, -0.4, 3.1)] {
            let q = nalgebra::UnitQuaternion::from_euler_angles(roll, pitch, yaw);
            let v = Value::List([q.i, q.j, q.k, q.w].map(Value::Float).to_vec());
            for (leaf, want) in [(Leaf::Roll, roll), (Leaf::Pitch, pitch), (Leaf::Yaw, yaw)] {
                assert!((number(&v, leaf).unwrap() - want).abs() < 1e-12, "{leaf:?} {want}");
            }
        }
    }
}
