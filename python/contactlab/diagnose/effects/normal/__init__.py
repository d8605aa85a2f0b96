"""Normal-contact effects (one module each, registered on import)."""
