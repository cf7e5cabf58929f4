//! What the host learns of a plugin library from its bytes alone, before
//! any of its code runs: that it is a complete shared object for this
//! machine, that its dynamic section points inside it, and which function
//! is its entry.
//!
//! The `object` crate reads the ELF structures (it returns errors, never
//! trusts an offset); the checks themselves are the loader's preconditions
//! that a damaged file breaks: a truncated library crashes the process that
//! maps it (SIGBUS), a dynamic pointer outside the library crashes the
//! loader. They give a clear reason early; the child process the library
//! is loaded in ([`super::remote`]) is what makes any other damage harmless.

use object::elf;
use object::read::elf::{Dyn, FileHeader, ProgramHeader, Sym};
use object::Endianness;
use std::path::Path;

/// The prefix of an entry's symbol.
pub const ENTRY_PREFIX: &str = "pilgrim_plugin_";

/// Why a library is refused before it is loaded.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Refusal {
    /// Not a complete shared object for this machine.
    NotLibrary(String),
    /// No entry, or no way to tell which.
    NoEntry(String),
}

/// Checks the library `path` and finds its entry: the one function it
/// exports named `pilgrim_plugin_*`, whatever the file is called. A library
/// exporting several (a test fixture) uses the one named after its file
/// (`libNAME.so`: `pilgrim_plugin_NAME`, `-` and `.` read as `_`).
pub(super) fn inspect(path: &Path) -> Result<String, Refusal> {
    let data = crate::files::read_bytes(path, crate::files::MAX_DATA_BYTES)
        .map_err(|e| Refusal::NotLibrary(e.message))?;
    // `object` is made not to panic on any input; should it, the library
    // is refused, not the host ended.
    std::panic::catch_unwind(|| check(&data, path)).unwrap_or_else(|_| {
        Err(Refusal::NotLibrary(incomplete(
            "its structure cannot be read",
        )))
    })
}

fn incomplete(what: &str) -> String {
    format!("not a complete shared object: {what} (the file is cut short or damaged)")
}

fn check(data: &[u8], path: &Path) -> Result<String, Refusal> {
    let not = |m: String| Refusal::NotLibrary(m);
    if !data.starts_with(&elf::ELFMAG) {
        return Err(not(
            "not an ELF shared object (pilgrim loads machine plugins built as .so libraries)"
                .into(),
        ));
    }
    let header = elf::FileHeader64::<Endianness>::parse(data).map_err(|_| {
        not(incomplete(
            "its ELF header cannot be read, or it is not a 64-bit library",
        ))
    })?;
    let endian = header
        .endian()
        .map_err(|_| not(incomplete("its byte order cannot be read")))?;
    if (endian == Endianness::Little) != cfg!(target_endian = "little") {
        return Err(not("a library for another byte order".into()));
    }
    let machine = if cfg!(target_arch = "x86_64") {
        Some(elf::EM_X86_64)
    } else if cfg!(target_arch = "aarch64") {
        Some(elf::EM_AARCH64)
    } else {
        None
    };
    if machine.is_some_and(|m| header.e_machine(endian) != m) {
        return Err(not(format!(
            "a library for another machine (ELF machine {})",
            header.e_machine(endian)
        )));
    }
    if header.e_type(endian) != elf::ET_DYN {
        return Err(not(format!(
            "not a shared object (ELF type {})",
            header.e_type(endian)
        )));
    }
    let phdrs = header
        .program_headers(endian, data)
        .map_err(|_| not(incomplete("its program headers lie beyond its end")))?;
    let mut loaded: Vec<(u64, u64)> = Vec::new();
    for ph in phdrs {
        if ph.p_type(endian) == elf::PT_LOAD {
            let end = ph.p_offset(endian).checked_add(ph.p_filesz(endian));
            if end.is_none_or(|e| e > data.len() as u64) {
                return Err(not(incomplete("a loaded segment lies beyond its end")));
            }
            let (at, size) = (ph.p_vaddr(endian), ph.p_memsz(endian));
            loaded.push((at, at.saturating_add(size)));
        }
    }
    for ph in phdrs {
        let dynamic = ph
            .dynamic(endian, data)
            .map_err(|_| not(incomplete("its dynamic section lies beyond its end")))?;
        if let Some(entries) = dynamic {
            check_dynamic(entries, endian, &loaded).map_err(|m| not(incomplete(&m)))?;
        }
    }
    entry(header, endian, data, path)
}

/// Checks that every address the dynamic section gives lies in a loaded
/// segment, with the length it states, and string offsets in the table.
fn check_dynamic(
    entries: &[elf::Dyn64<Endianness>],
    endian: Endianness,
    loaded: &[(u64, u64)],
) -> Result<(), String> {
    let value = |tag: elf::DynamicTag| {
        entries
            .iter()
            .find(|d| d.d_tag(endian) == tag)
            .map(|d| d.d_val(endian))
    };
    let inside = |at: u64, len: u64| {
        loaded
            .iter()
            .any(|&(start, end)| at >= start && at.checked_add(len).is_some_and(|e| e <= end))
    };
    let sized = [
        (elf::DT_STRTAB, Some(elf::DT_STRSZ), "DT_STRTAB"),
        (elf::DT_RELA, Some(elf::DT_RELASZ), "DT_RELA"),
        (elf::DT_REL, Some(elf::DT_RELSZ), "DT_REL"),
        (elf::DT_JMPREL, Some(elf::DT_PLTRELSZ), "DT_JMPREL"),
        (
            elf::DT_INIT_ARRAY,
            Some(elf::DT_INIT_ARRAYSZ),
            "DT_INIT_ARRAY",
        ),
        (
            elf::DT_FINI_ARRAY,
            Some(elf::DT_FINI_ARRAYSZ),
            "DT_FINI_ARRAY",
        ),
        (elf::DT_SYMTAB, None, "DT_SYMTAB"),
        (elf::DT_HASH, None, "DT_HASH"),
        (elf::DT_GNU_HASH, None, "DT_GNU_HASH"),
        (elf::DT_INIT, None, "DT_INIT"),
        (elf::DT_FINI, None, "DT_FINI"),
        (elf::DT_PLTGOT, None, "DT_PLTGOT"),
        (elf::DT_VERSYM, None, "DT_VERSYM"),
        (elf::DT_VERDEF, None, "DT_VERDEF"),
        (elf::DT_VERNEED, None, "DT_VERNEED"),
    ];
    for (tag, size_tag, name) in sized {
        let Some(at) = value(tag) else { continue };
        let len = size_tag.and_then(value).unwrap_or(1);
        if !inside(at, len.max(1)) {
            return Err(format!(
                "its dynamic section's {name} points outside the library"
            ));
        }
    }
    if value(elf::DT_STRTAB).is_none() {
        return Err("its dynamic section has no string table".into());
    }
    let strings = value(elf::DT_STRSZ).unwrap_or(0);
    for d in entries {
        let tag = d.d_tag(endian);
        let named = [
            elf::DT_NEEDED,
            elf::DT_SONAME,
            elf::DT_RPATH,
            elf::DT_RUNPATH,
        ];
        if named.contains(&tag) && d.d_val(endian) >= strings {
            return Err("its dynamic section names a string outside its string table".into());
        }
    }
    Ok(())
}

/// The entry's symbol: the one exported function named `pilgrim_plugin_*`,
/// or, among several, the one named after the file.
fn entry(
    header: &elf::FileHeader64<Endianness>,
    endian: Endianness,
    data: &[u8],
    path: &Path,
) -> Result<String, Refusal> {
    let by_name = file_entry(path);
    let sections = header
        .sections(endian, data)
        .map_err(|_| Refusal::NotLibrary(incomplete("its section headers cannot be read")))?;
    let symbols = sections
        .symbols(endian, data, elf::SHT_DYNSYM)
        .map_err(|_| Refusal::NotLibrary(incomplete("its symbol table cannot be read")))?;
    let mut entries: Vec<String> = Vec::new();
    for s in symbols.iter() {
        if s.st_type() != elf::STT_FUNC || s.st_shndx(endian) == elf::SHN_UNDEF {
            continue;
        }
        let Ok(name) = s.name(endian, symbols.strings()) else {
            continue;
        };
        if let Ok(name) = std::str::from_utf8(name) {
            if name.starts_with(ENTRY_PREFIX) && !entries.iter().any(|e| e == name) {
                entries.push(name.to_owned());
            }
        }
    }
    match entries.len() {
        0 => Err(Refusal::NoEntry(format!(
            "the library exports no function named {ENTRY_PREFIX}* (a pilgrim machine plugin exports one: export_plugin! in Rust, PILGRIM_PLUGIN_ENTRY in C)"
        ))),
        1 => Ok(entries.remove(0)),
        _ if entries.contains(&by_name) => Ok(by_name),
        n => {
            entries.sort();
            entries.truncate(5);
            Err(Refusal::NoEntry(format!(
                "the library exports {n} entries ({}{}) and none is named for its file ({by_name}): a plugin library exports one",
                entries.join(", "),
                if n > 5 { ", ..." } else { "" }
            )))
        }
    }
}

/// The entry named after the library's file: `pilgrim_plugin_<stem>`.
fn file_entry(path: &Path) -> String {
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("");
    let stem = stem.strip_prefix("lib").unwrap_or(stem);
    format!("{ENTRY_PREFIX}{}", stem.replace(['-', '.'], "_"))
}
