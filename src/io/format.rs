//! Numbers, sizes and settings' names written for people: shortest
//! round-trip numbers, significant digits, byte counts in binary units,
//! a setting by its key or its flag ([`SettingNames`]).

/// A number for a message: plain for ordinary magnitudes, scientific for
/// extreme ones (1e308 is not printed as 309 digits).
pub fn fmt_num(v: f64) -> String {
    if v != 0.0 && v.is_finite() && !(1e-4..1e9).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// A byte count for a message, in binary units: `512 B`, `3.2 MiB`, `236.7 GiB`.
pub fn fmt_bytes(bytes: u64) -> String {
    const UNITS: [&str; 6] = ["B", "KiB", "MiB", "GiB", "TiB", "PiB"];
    let mut value = bytes as f64;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    if unit == 0 {
        format!("{bytes} B")
    } else {
        format!("{value:.1} {}", UNITS[unit])
    }
}

/// A number rounded to `digits` significant digits for people to read (whole
/// numbers keep their integer digits: 1234, not 1230):
/// plain decimal for ordinary magnitudes (1e-4 ≤ |v| < 1e6), scientific
/// otherwise, trailing zeros dropped (`1.54`, `-0.01235`, `3.2e-7`, not
/// `1.5400e0` or `-0.012345678901234567`). Files keep full precision.
pub fn fmt_sig(v: f64, digits: usize) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = digits.max(1);
    let trim = |m: &str| if m.contains('.') { m.trim_end_matches('0').trim_end_matches('.').to_string() } else { m.to_string() };
    if !(1e-4..1e6).contains(&v.abs()) {
        let text = format!("{v:.prec$e}", prec = digits - 1);
        let (mantissa, exponent) = text.split_once('e').expect("scientific format has an exponent");
        return format!("{}e{exponent}", trim(mantissa));
    }
    let decimals = (digits as i32 - 1 - v.abs().log10().floor() as i32).max(0) as usize;
    trim(&format!("{v:.decimals$}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_for_people_have_the_significant_digits_asked_for() {
        assert_eq!(fmt_sig(1.54, 3), "1.54");
        assert_eq!(fmt_sig(1.5400000001, 5), "1.54");
        assert_eq!(fmt_sig(-0.012345678901234567, 4), "-0.01235");
        assert_eq!(fmt_sig(115.1172, 5), "115.12");
        assert_eq!(fmt_sig(12345.67, 5), "12346");
        assert_eq!(fmt_sig(9.99996, 5), "10");
        assert_eq!(fmt_sig(3.2e-7, 3), "3.2e-7");
        assert_eq!(fmt_sig(-4.56789e8, 3), "-4.57e8");
        assert_eq!(fmt_sig(0.0, 3), "0");
        assert_eq!(fmt_sig(f64::NAN, 3), "NaN");
    }

    #[test]
    fn byte_counts_read_in_binary_units() {
        assert_eq!(fmt_bytes(512), "512 B");
        assert_eq!(fmt_bytes(512 << 20), "512.0 MiB");
        assert_eq!(fmt_bytes(u64::MAX), "16384.0 PiB");
    }
}

/// How a message names a setting a user gave: by its key (`a0_bounds`,
/// the fields of a request and Python's keywords) or by its flag
/// (`--a0-bounds`, the command line's).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SettingNames {
    /// Keys, as the fields and Python's keywords are named.
    Keys,
    /// The command line's flags.
    Flags,
}

impl SettingNames {
    /// The name of the setting with key `key`, whose flag is the key's words joined by `-`.
    pub fn name(self, key: &'static str) -> String {
        match self {
            SettingNames::Keys => key.to_string(),
            SettingNames::Flags => format!("--{}", key.replace('_', "-")),
        }
    }

    /// `key` or `flag`: the name of a setting whose flag is not its key's words.
    pub fn either(self, key: &'static str, flag: &'static str) -> &'static str {
        match self {
            SettingNames::Keys => key,
            SettingNames::Flags => flag,
        }
    }
}
