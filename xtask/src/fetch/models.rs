//! A minimal reader for the `<Models>` header of a NodeSet2 file.
//!
//! Only `--update-lock` needs it, to record which model each file defines and
//! which models it requires. It deliberately avoids an XML library to keep
//! xtask quick to build: it walks the tags from the start of the document,
//! skips comments and processing instructions, reads the attributes of
//! `<Model>` and `<RequiredModel>`, and stops at `</Models>`. The real parser
//! lives in the nodeset-compiler crate.

/// One `<Model>` element and the `<RequiredModel>` elements nested in it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ModelHeader {
    pub uri: String,
    pub version: Option<String>,
    pub publication_date: Option<String>,
    pub required: Vec<RequiredModel>,
}

/// One `<RequiredModel>` element.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RequiredModel {
    pub uri: String,
    pub version: Option<String>,
}

/// Reads every `<Model>` declared in the `<Models>` element of a NodeSet2 document.
///
/// A document without a `<Models>` element (allowed by the schema, and seen in
/// old files) yields an empty list.
pub fn read_models(document: &str) -> Result<Vec<ModelHeader>, String> {
    let mut models: Vec<ModelHeader> = Vec::new();
    let mut rest = document.strip_prefix('\u{feff}').unwrap_or(document);
    let mut inside_models = false;

    while let Some(start) = rest.find('<') {
        rest = &rest[start..];
        // Comments and processing instructions may contain `<` and `>`, so skip them whole.
        if let Some(after) = rest.strip_prefix("<!--") {
            let end = after.find("-->").ok_or("unterminated XML comment")?;
            rest = &after[end + 3..];
            continue;
        }
        if let Some(after) = rest.strip_prefix("<?") {
            let end = after
                .find("?>")
                .ok_or("unterminated processing instruction")?;
            rest = &after[end + 2..];
            continue;
        }
        let end = rest.find('>').ok_or("unterminated XML tag")?;
        let tag = &rest[1..end];
        rest = &rest[end + 1..];

        // The element name runs up to the first space; `/` may end a self-closing tag.
        let name = tag
            .split(|c: char| c.is_ascii_whitespace())
            .next()
            .unwrap_or("")
            .trim_end_matches('/');
        match name {
            "Models" => {
                if tag.trim_end().ends_with('/') {
                    break;
                }
                inside_models = true;
            }
            "Model" if inside_models => models.push(ModelHeader {
                uri: required_attribute(tag, "Model", "ModelUri")?,
                version: attribute(tag, "Version")?,
                publication_date: attribute(tag, "PublicationDate")?,
                required: Vec::new(),
            }),
            "RequiredModel" if inside_models => {
                let required = RequiredModel {
                    uri: required_attribute(tag, "RequiredModel", "ModelUri")?,
                    version: attribute(tag, "Version")?,
                };
                models
                    .last_mut()
                    .ok_or("<RequiredModel> appears before any <Model>")?
                    .required
                    .push(required);
            }
            "/Models" => break,
            // The header elements come first; once node definitions start there is no <Models>.
            "UAObject" | "UAVariable" | "UAMethod" | "UAObjectType" | "UAVariableType"
            | "UADataType" | "UAReferenceType" | "UAView" => break,
            _ => {}
        }
    }
    Ok(models)
}

/// Like [`attribute`], but a missing attribute is an error naming the element.
fn required_attribute(tag: &str, element: &str, name: &str) -> Result<String, String> {
    attribute(tag, name)?.ok_or_else(|| format!("<{element}> has no {name} attribute"))
}

/// Returns the unescaped value of attribute `name` in the text of a start tag.
fn attribute(tag: &str, name: &str) -> Result<Option<String>, String> {
    let mut rest = tag;
    while let Some(position) = rest.find(name) {
        let before = rest[..position].chars().next_back();
        let after = rest[position + name.len()..].trim_start();
        rest = &rest[position + name.len()..];
        // The name must be a whole attribute name followed by `=`.
        if !before.is_some_and(|c| c.is_ascii_whitespace()) {
            continue;
        }
        let Some(value_part) = after.strip_prefix('=') else {
            continue;
        };
        let value_part = value_part.trim_start();
        let quote = value_part
            .chars()
            .next()
            .filter(|&c| c == '"' || c == '\'')
            .ok_or_else(|| format!("attribute {name} has an unquoted value"))?;
        let value = &value_part[1..];
        let end = value
            .find(quote)
            .ok_or_else(|| format!("attribute {name} has an unterminated value"))?;
        return unescape(&value[..end]).map(Some);
    }
    Ok(None)
}

/// Replaces the five predefined XML entities and numeric character references.
fn unescape(value: &str) -> Result<String, String> {
    let mut out = String::with_capacity(value.len());
    let mut rest = value;
    while let Some(amp) = rest.find('&') {
        out.push_str(&rest[..amp]);
        let after = &rest[amp + 1..];
        let semi = after
            .find(';')
            .ok_or_else(|| format!("unterminated entity in `{value}`"))?;
        let entity = &after[..semi];
        let replacement = match entity {
            "amp" => '&',
            "lt" => '<',
            "gt" => '>',
            "quot" => '"',
            "apos" => '\'',
            _ => {
                let code = if let Some(hex) = entity.strip_prefix("#x") {
                    u32::from_str_radix(hex, 16).ok()
                } else if let Some(decimal) = entity.strip_prefix('#') {
                    decimal.parse().ok()
                } else {
                    None
                };
                code.and_then(char::from_u32)
                    .ok_or_else(|| format!("unknown entity `&{entity};` in `{value}`"))?
            }
        };
        out.push(replacement);
        rest = &after[semi + 1..];
    }
    out.push_str(rest);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_model_and_required_models() {
        let document = r#"<?xml version="1.0" encoding="utf-8" ?>
<!-- A comment that mentions <Models> must not confuse the scanner. -->
<UANodeSet xmlns="http://opcfoundation.org/UA/2011/03/UANodeSet.xsd">
  <NamespaceUris><Uri>http://example.org/A/</Uri></NamespaceUris>
  <Models>
    <Model ModelUri="http://example.org/A/" Version="1.02" PublicationDate="2025-09-08T00:00:00Z" ModelVersion="1.2">
      <RequiredModel ModelUri="http://opcfoundation.org/UA/" Version="1.05.03" />
      <RequiredModel ModelUri='http://example.org/B/?x=1&amp;y=2' />
    </Model>
  </Models>
  <UAObject NodeId="ns=1;i=1" BrowseName="1:X"><Models/></UAObject>
</UANodeSet>"#;
        let models = read_models(document).expect("header parses");
        assert_eq!(
            models,
            vec![ModelHeader {
                uri: "http://example.org/A/".to_string(),
                version: Some("1.02".to_string()),
                publication_date: Some("2025-09-08T00:00:00Z".to_string()),
                required: vec![
                    RequiredModel {
                        uri: "http://opcfoundation.org/UA/".to_string(),
                        version: Some("1.05.03".to_string()),
                    },
                    RequiredModel {
                        uri: "http://example.org/B/?x=1&y=2".to_string(),
                        version: None,
                    },
                ],
            }]
        );
    }

    #[test]
    fn attribute_names_must_match_whole_words() {
        // `ModelVersion` must not be mistaken for `Version`.
        let tag = r#"Model ModelUri="u" ModelVersion="9.9" Version="1.0""#;
        assert_eq!(attribute(tag, "Version"), Ok(Some("1.0".to_string())));
        assert_eq!(attribute(tag, "PublicationDate"), Ok(None));
    }

    #[test]
    fn document_without_models_yields_nothing() {
        let document = "\u{feff}<?xml version=\"1.0\"?><UANodeSet><Aliases/><UAObject NodeId=\"i=1\"/></UANodeSet>";
        assert_eq!(read_models(document), Ok(Vec::new()));
    }

    #[test]
    fn required_model_without_uri_is_an_error() {
        let document = r#"<UANodeSet><Models><Model ModelUri="u"><RequiredModel Version="1"/></Model></Models></UANodeSet>"#;
        let error = read_models(document).unwrap_err();
        assert!(
            error.contains("RequiredModel") && error.contains("ModelUri"),
            "{error}"
        );
    }
}
