//! The three byte orders of C3D files (the processor type in the parameter section): Intel
//! (little-endian IEEE), DEC (little-endian words, VAX F floats) and SGI/MIPS (big-endian IEEE).

/// The processor that wrote a C3D file, which fixes its byte order and float format.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) enum Processor {
    /// Intel: little-endian, IEEE floats (processor byte 84).
    #[default]
    Intel,
    /// DEC (VAX): little-endian 16-bit words, VAX F floats (processor byte 85).
    Dec,
    /// SGI/MIPS: big-endian, IEEE floats (processor byte 86).
    Mips,
}

impl Processor {
    /// The processor from the parameter section's fourth byte (83 + type).
    pub(crate) fn from_byte(b: u8) -> Option<Processor> {
        match b {
            84 => Some(Processor::Intel),
            85 => Some(Processor::Dec),
            86 => Some(Processor::Mips),
            _ => None,
        }
    }

    /// An unsigned 16-bit word.
    pub(crate) fn u16(self, b: [u8; 2]) -> u16 {
        match self {
            Processor::Mips => u16::from_be_bytes(b),
            _ => u16::from_le_bytes(b),
        }
    }

    /// A signed 16-bit word.
    pub(crate) fn i16(self, b: [u8; 2]) -> i16 {
        self.u16(b) as i16
    }

    /// A 32-bit float.
    pub(crate) fn f32(self, b: [u8; 4]) -> f32 {
        match self {
            Processor::Intel => f32::from_le_bytes(b),
            Processor::Mips => f32::from_be_bytes(b),
            // VAX F: the high word first; exponent bias 128 and hidden bit 0.1f give a factor 4
            Processor::Dec => f32::from_le_bytes([b[2], b[3], b[0], b[1]]) / 4.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_three_byte_orders_read_one_and_a_half() {
        assert_eq!(Processor::Intel.f32(1.5f32.to_le_bytes()), 1.5);
        assert_eq!(Processor::Mips.f32(1.5f32.to_be_bytes()), 1.5);
        // VAX F 1.5: sign 0, exponent 129, fraction .1 → words 0x40C0, 0x0000
        assert_eq!(Processor::Dec.f32([0xC0, 0x40, 0x00, 0x00]), 1.5);
        assert_eq!(Processor::Mips.i16([0xFF, 0xFE]), -2);
        assert_eq!(Processor::Intel.u16([0x34, 0x12]), 0x1234);
    }
}
