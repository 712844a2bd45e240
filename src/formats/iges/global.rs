//! The Global section (IGES 5.3 §2.2.4): the delimiters every later parameter depends on, and
//! the unit and model scale that turn model coordinates into millimetres. Descriptive strings are
//! kept for inventories and messages; fields a writer left empty or omitted at the end take the
//! standard's defaults.

use super::error::{IgesError, shown, shown_str};
use super::free::{Joined, Located, Token, latin1, number, tokenize};
use super::records::{DATA_COLUMNS, Record};

/// The unit of model-space lengths (global parameters 14 and 15).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unit {
    Inch,
    Millimetre,
    Foot,
    Mile,
    Metre,
    Kilometre,
    /// A thousandth of an inch.
    Mil,
    Micron,
    Centimetre,
    Microinch,
}

impl Unit {
    /// Millimetres per unit, to bring a file's coordinates into the millimetres the viewer and
    /// the reference data use.
    #[must_use]
    pub fn millimetres(self) -> f64 {
        match self {
            Self::Inch => 25.4,
            Self::Millimetre => 1.0,
            Self::Foot => 304.8,
            Self::Mile => 1_609_344.0,
            Self::Metre => 1000.0,
            Self::Kilometre => 1_000_000.0,
            Self::Mil => 0.0254,
            Self::Micron => 0.001,
            Self::Centimetre => 10.0,
            Self::Microinch => 0.000_025_4,
        }
    }

    /// The unit of units flag `flag` (1 inch, 2 mm, 4 ft, 5 mi, 6 m, 7 km, 8 mil, 9 micron,
    /// 10 cm, 11 microinch); flag 3 means "named by `name`" and takes the names of §2.2.4.3.
    #[must_use]
    pub fn from_flag(flag: i64, name: &str) -> Option<Self> {
        Some(match flag {
            1 => Self::Inch,
            2 => Self::Millimetre,
            3 => return Self::from_name(name),
            4 => Self::Foot,
            5 => Self::Mile,
            6 => Self::Metre,
            7 => Self::Kilometre,
            8 => Self::Mil,
            9 => Self::Micron,
            10 => Self::Centimetre,
            11 => Self::Microinch,
            _ => return None,
        })
    }

    /// The unit a units name stands for (`IN`/`INCH`, `MM`, `FT`, `MI`, `M`, `KM`, `MIL`, `UM`,
    /// `CM`, `UIN`, and a few spelled-out variants), ignoring case and blanks.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Some(match name.trim().to_ascii_uppercase().as_str() {
            "IN" | "INCH" | "INCHES" => Self::Inch,
            "MM" | "MILLIMETER" | "MILLIMETRE" => Self::Millimetre,
            "FT" | "FOOT" | "FEET" => Self::Foot,
            "MI" | "MILE" | "MILES" => Self::Mile,
            "M" | "METER" | "METRE" => Self::Metre,
            "KM" | "KILOMETER" | "KILOMETRE" => Self::Kilometre,
            "MIL" | "MILS" => Self::Mil,
            "UM" | "MICRON" | "MICRONS" => Self::Micron,
            "CM" | "CENTIMETER" | "CENTIMETRE" => Self::Centimetre,
            "UIN" | "MICROINCH" => Self::Microinch,
            _ => return None,
        })
    }
}

/// The Global section, fields numbered as in IGES 5.3 §2.2.4 in the comments.
#[derive(Debug, Clone, PartialEq)]
pub struct Global {
    /// 1: separates parameters (default `,`).
    pub parameter_delimiter: u8,
    /// 2: ends an entity's parameters (default `;`).
    pub record_delimiter: u8,
    /// 3: product identification from the sender.
    pub product_id: String,
    /// 4: file name.
    pub file_name: String,
    /// 5: native system id (the CAD system that wrote the file).
    pub native_system: String,
    /// 6: preprocessor (IGES writer) version.
    pub preprocessor_version: String,
    /// 7: bits of an integer on the sending system.
    pub integer_bits: i64,
    /// 8–9: single precision maximum power of ten and significant digits.
    pub single_magnitude: i64,
    pub single_significance: i64,
    /// 10–11: double precision maximum power of ten and significant digits.
    pub double_magnitude: i64,
    pub double_significance: i64,
    /// 12: product identification for the receiver.
    pub receiver_product_id: String,
    /// 13: model space scale, model size over real-world size (1.0 when empty).
    pub model_scale: f64,
    /// 14 (and 15): the unit of model-space lengths. The flag decides; the name is only read
    /// for flag 3, as the standard says, so a file saying `2` and `INCH` is in millimetres.
    pub unit: Unit,
    /// 14: the units flag as written (1 when empty).
    pub units_flag: i64,
    /// 15: the units name as written.
    pub units_name: String,
    /// 16: number of line weight gradations.
    pub line_weight_gradations: i64,
    /// 17: width of the maximum line weight, in units.
    pub max_line_weight: f64,
    /// 18: date and time the file was generated.
    pub generated: String,
    /// 19: minimum user-intended resolution, in units.
    pub min_resolution: f64,
    /// 20: approximate maximum coordinate value, in units (0.0 = not given).
    pub max_coordinate: f64,
    /// 21: author.
    pub author: String,
    /// 22: author's organisation.
    pub organisation: String,
    /// 23: IGES version flag (11 = 5.3).
    pub version: i64,
    /// 24: drafting standard flag.
    pub drafting_standard: i64,
    /// 25: date and time the model was created or last modified.
    pub modified: String,
    /// 26: application protocol or subset identifier.
    pub application_protocol: String,
}

impl Global {
    /// Millimetres per model-space unit, the factor that brings coordinates into millimetres.
    #[must_use]
    pub fn mm_per_unit(&self) -> f64 {
        self.unit.millimetres()
    }
}

const FIELD_NAMES: [&str; 26] = [
    "parameter delimiter",
    "record delimiter",
    "product id",
    "file name",
    "native system id",
    "preprocessor version",
    "integer bits",
    "single precision magnitude",
    "single precision significance",
    "double precision magnitude",
    "double precision significance",
    "receiver product id",
    "model space scale",
    "units flag",
    "units name",
    "line weight gradations",
    "maximum line weight",
    "file generation date",
    "minimum resolution",
    "maximum coordinate",
    "author",
    "organisation",
    "version flag",
    "drafting standard flag",
    "model modification date",
    "application protocol",
];

/// Reads the Global section from its records.
pub(super) fn parse(records: &[Record<'_>]) -> Result<Global, IgesError> {
    let joined = Joined::new(DATA_COLUMNS, records.iter().map(|r| (r.line, r.data)));
    let first_line = records.first().map_or(1, |r| r.line);
    let (parameter, record) = delimiters(&joined.bytes)
        .map_err(|(index, message)| global_error(first_line, index, message))?;
    let tokens = tokenize(&joined, parameter, record).map_err(|e| IgesError::Layout {
        line: e.line,
        message: format!("Global section: {}", e.message),
    })?;
    let fields = Fields {
        tokens: &tokens,
        last_line: records.last().map_or(1, |r| r.line),
    };
    let units_flag = fields.int(14, 1)?;
    let units_name = fields.string(15);
    let unit = Unit::from_flag(units_flag, &units_name).ok_or_else(|| {
        let (index, message) = if units_flag == 3 {
            (
                15,
                format!("'{}' is not an IGES unit name", shown_str(&units_name)),
            )
        } else {
            (
                14,
                format!("is {units_flag}, not an IGES units flag (1-11)"),
            )
        };
        global_error(fields.line(index), index, message)
    })?;
    let model_scale = fields.real(13, 1.0)?;
    if model_scale <= 0.0 {
        return Err(global_error(
            fields.line(13),
            13,
            format!("is {model_scale}, but a scale must be positive"),
        ));
    }
    Ok(Global {
        parameter_delimiter: parameter,
        record_delimiter: record,
        product_id: fields.string(3),
        file_name: fields.string(4),
        native_system: fields.string(5),
        preprocessor_version: fields.string(6),
        integer_bits: fields.int(7, 0)?,
        single_magnitude: fields.int(8, 0)?,
        single_significance: fields.int(9, 0)?,
        double_magnitude: fields.int(10, 0)?,
        double_significance: fields.int(11, 0)?,
        receiver_product_id: fields.string(12),
        model_scale,
        unit,
        units_flag,
        units_name,
        line_weight_gradations: fields.int(16, 1)?,
        max_line_weight: fields.real(17, 0.0)?,
        generated: fields.string(18),
        min_resolution: fields.real(19, 0.0)?,
        max_coordinate: fields.real(20, 0.0)?,
        author: fields.string(21),
        organisation: fields.string(22),
        version: fields.int(23, 3)?,
        drafting_standard: fields.int(24, 0)?,
        modified: fields.string(25),
        application_protocol: fields.string(26),
    })
}

#[must_use]
fn global_error(line: usize, index: usize, message: String) -> IgesError {
    IgesError::Global {
        line,
        index,
        name: FIELD_NAMES.get(index - 1).copied().unwrap_or("unknown"),
        message,
    }
}

/// The delimiters declared by fields 1 and 2 (`1H,` or empty for the default), checked against
/// the characters the standard forbids as delimiters (blank, digits, `+ - . D E H`), since a
/// delimiter that can occur inside a number would make the rest ambiguous.
fn delimiters(text: &[u8]) -> Result<(u8, u8), (usize, String)> {
    let (parameter, after) = declared(text, 0).map_err(|m| (1, m))?;
    let parameter = parameter.unwrap_or(b',');
    if text.get(after) != Some(&parameter) {
        return Err((
            1,
            format!(
                "should be followed by the parameter delimiter '{}', found '{}'",
                char::from(parameter),
                shown(text.get(after..after + 1).unwrap_or_default())
            ),
        ));
    }
    let (record, _) = declared(text, after + 1).map_err(|m| (2, m))?;
    let record = record.unwrap_or(b';');
    for (index, delimiter) in [(1, parameter), (2, record)] {
        if delimiter == b' ' || delimiter.is_ascii_digit() || b"+-.DEHdeh".contains(&delimiter) {
            return Err((
                index,
                format!(
                    "is '{}', which the standard forbids as a delimiter",
                    shown(&[delimiter])
                ),
            ));
        }
    }
    if parameter == record {
        return Err((
            2,
            format!(
                "is '{}', the same as the parameter delimiter",
                char::from(record)
            ),
        ));
    }
    Ok((parameter, record))
}

/// A delimiter field at `pos`: `1Hc` gives `Some(c)`, blanks only give `None` (the default);
/// returns the offset after the field as well.
fn declared(text: &[u8], pos: usize) -> Result<(Option<u8>, usize), String> {
    let start = pos
        + text
            .get(pos..)
            .map_or(0, |t| t.iter().take_while(|&&b| b == b' ').count());
    let rest = text.get(start..).unwrap_or_default();
    let digits = rest.iter().take_while(|b| b.is_ascii_digit()).count();
    if digits == 0 || !matches!(rest.get(digits), Some(b'H' | b'h')) {
        return Ok((None, start));
    }
    if rest.get(..digits) != Some(b"1") {
        return Err(format!(
            "should be one character written as 1Hc, found '{}'",
            shown(rest.get(..digits + 2).unwrap_or(rest))
        ));
    }
    match rest.get(digits + 1) {
        Some(&c) => Ok((Some(c), start + digits + 2)),
        None => Err("ends the Global section inside its Hollerith string".to_owned()),
    }
}

/// Typed access to the tokens of the Global section by field number.
struct Fields<'t, 'a> {
    tokens: &'t [Located<'a>],
    last_line: usize,
}

impl Fields<'_, '_> {
    #[must_use]
    fn line(&self, index: usize) -> usize {
        self.tokens
            .get(index - 1)
            .map_or(self.last_line, |t| t.line)
    }

    #[must_use]
    /// A string field; an unquoted value is taken as written, since only descriptive fields are
    /// strings and their exact form matters to nobody.
    fn string(&self, index: usize) -> String {
        match self.tokens.get(index - 1).map(|t| &t.token) {
            Some(Token::Text(text)) => text.clone(),
            Some(Token::Plain(raw)) => latin1(raw),
            None => String::new(),
        }
    }

    fn int(&self, index: usize, default: i64) -> Result<i64, IgesError> {
        match self.tokens.get(index - 1).map(|t| &t.token) {
            None => Ok(default),
            Some(Token::Plain(raw)) => match number(raw) {
                super::free::Number::Empty => Ok(default),
                super::free::Number::Int(v) => Ok(v),
                _ => Err(self.wrong(index, "an integer", &latin1(raw))),
            },
            Some(Token::Text(text)) => Err(self.wrong(index, "an integer", text)),
        }
    }

    fn real(&self, index: usize, default: f64) -> Result<f64, IgesError> {
        match self.tokens.get(index - 1).map(|t| &t.token) {
            None => Ok(default),
            Some(Token::Plain(raw)) => match number(raw) {
                super::free::Number::Empty => Ok(default),
                super::free::Number::Int(v) => Ok(v as f64),
                super::free::Number::Real(v) => Ok(v),
                super::free::Number::Invalid => Err(self.wrong(index, "a real", &latin1(raw))),
            },
            Some(Token::Text(text)) => Err(self.wrong(index, "a real", text)),
        }
    }

    #[must_use]
    fn wrong(&self, index: usize, what: &str, found: &str) -> IgesError {
        global_error(
            self.line(index),
            index,
            format!("should be {what}, found '{}'", shown_str(found)),
        )
    }
}
