//! `f64` fields that may be infinite (the PSNR of a frame equal to its reference) or
//! NaN, which JSON numbers cannot hold: written as the strings `inf`, `-inf`, `NaN`.

use serde::{de, Deserialize, Deserializer, Serializer};

#[derive(Deserialize)]
#[serde(untagged)]
enum Number {
    Finite(f64),
    Text(String),
}

pub fn serialize<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
    if v.is_finite() {
        s.serialize_f64(*v)
    } else {
        s.serialize_str(&v.to_string())
    }
}

pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    match Number::deserialize(d)? {
        Number::Finite(v) => Ok(v),
        Number::Text(t) => t.parse().map_err(de::Error::custom),
    }
}

/// The same for `Option<f64>` (`null` for none).
pub mod option {
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(v: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
        match v {
            Some(v) => super::serialize(v, s),
            None => s.serialize_none(),
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
        #[derive(Deserialize)]
        struct Wrapped(#[serde(with = "super")] f64);
        Ok(Option::<Wrapped>::deserialize(d)?.map(|w| w.0))
    }
}

#[cfg(test)]
mod tests {
    use serde::{Deserialize, Serialize};

    #[derive(Serialize, Deserialize, PartialEq, Debug)]
    struct Row {
        #[serde(with = "super")]
        a: f64,
        #[serde(with = "super::option")]
        b: Option<f64>,
    }

    #[test]
    fn floats_round_trip_exactly_including_infinity() {
        for row in [
            Row {
                a: f64::INFINITY,
                b: None,
            },
            Row {
                a: 0.1 + 0.2,
                b: Some(f64::NEG_INFINITY),
            },
            Row {
                a: 31.876_543_210_987_654,
                b: Some(1e-300),
            },
        ] {
            let text = serde_json::to_string(&row).unwrap();
            let back: Row = serde_json::from_str(&text).unwrap();
            assert_eq!(back, row, "{text}");
            assert_eq!(back.a.to_bits(), row.a.to_bits());
        }
        let nan: Row = serde_json::from_str(r#"{"a": "NaN", "b": null}"#).unwrap();
        assert!(nan.a.is_nan());
    }
}
