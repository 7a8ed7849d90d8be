//! `import`: scripts under the scene's folder only, read through weft's one
//! reader, each evaluated once, cycles refused naming the chain.

use super::*;

/// How deeply imports may nest (a script importing one that imports another…).
pub const MAX_IMPORT_DEPTH: usize = 16;

/// `import` for scripts under one folder only, read through weft's one
/// reader; records what it read, and refuses an import cycle (which would
/// otherwise recurse until the stack overflows) naming the chain.
pub(super) struct FolderResolver {
    root: PathBuf,
    read: Arc<Mutex<Vec<PathBuf>>>,
    /// The scripts being evaluated, outermost (the scene's script) first.
    resolving: Mutex<Vec<PathBuf>>,
    /// Modules already evaluated, by file, so a script imported by several
    /// (or inside `update`) is read and run once.
    modules: Mutex<HashMap<PathBuf, RhaiShared<Module>>>,
}

impl FolderResolver {
    pub(super) fn new(root: PathBuf, script: &Path, read: Arc<Mutex<Vec<PathBuf>>>) -> Self {
        let script = script
            .canonicalize()
            .unwrap_or_else(|_| script.to_path_buf());
        Self {
            root,
            read,
            resolving: Mutex::new(vec![script]),
            modules: Mutex::new(HashMap::new()),
        }
    }

    /// Reads, compiles and runs one imported file.
    fn evaluate(
        &self,
        engine: &Engine,
        file: &Path,
        path: &str,
        position: Position,
    ) -> Result<RhaiShared<Module>, Box<EvalAltResult>> {
        let text =
            crate::source::read_text(file, &Location::file(file), crate::source::MAX_SCENE_BYTES)
                .map_err(|e| {
                EvalAltResult::ErrorRuntime(format!("import \"{path}\": {e}").into(), position)
            })?;
        let in_module = |e: Box<EvalAltResult>| {
            Box::new(EvalAltResult::ErrorInModule(path.to_string(), e, position))
        };
        let mut ast = engine.compile(&text).map_err(|e| in_module(e.into()))?;
        ast.set_source(file.to_string_lossy().as_ref());
        let module = Module::eval_ast_as_new(Scope::new(), &ast, engine).map_err(in_module)?;
        Ok(module.into())
    }
}

impl ModuleResolver for FolderResolver {
    fn resolve(
        &self,
        engine: &Engine,
        _source: Option<&str>,
        path: &str,
        position: Position,
    ) -> Result<RhaiShared<Module>, Box<EvalAltResult>> {
        let refuse =
            |message: String| Err(EvalAltResult::ErrorRuntime(message.into(), position).into());
        let file = self.root.join(format!("{path}.rhai"));
        let Some(canonical) = file
            .canonicalize()
            .ok()
            .filter(|f| f.starts_with(&self.root))
        else {
            return refuse(format!(
                "import \"{path}\": scripts may import only scripts under {}",
                self.root.display()
            ));
        };
        {
            let mut read = lock(&self.read);
            if !read.contains(&file) {
                read.push(file.clone());
            }
        }
        if let Some(module) = lock(&self.modules).get(&canonical) {
            return Ok(module.clone());
        }
        {
            let mut resolving = lock(&self.resolving);
            if let Some(first) = resolving.iter().position(|f| *f == canonical) {
                let chain: Vec<String> = resolving[first..]
                    .iter()
                    .chain(std::iter::once(&canonical))
                    .map(|f| {
                        f.file_name()
                            .unwrap_or_default()
                            .to_string_lossy()
                            .into_owned()
                    })
                    .collect();
                return refuse(format!(
                    "import \"{path}\" is a cycle: {}",
                    chain.join(" -> ")
                ));
            }
            if resolving.len() > MAX_IMPORT_DEPTH {
                return refuse(format!(
                    "import \"{path}\": imports nest deeper than {MAX_IMPORT_DEPTH} scripts"
                ));
            }
            resolving.push(canonical.clone());
        }
        let module = self.evaluate(engine, &file, path, position);
        lock(&self.resolving).pop();
        let module = module?;
        lock(&self.modules).insert(canonical, module.clone());
        Ok(module)
    }
}
