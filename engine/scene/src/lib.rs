//! Scenes for weft: `.scene` files, OBJ/MTL and glTF models, lights and animation.
