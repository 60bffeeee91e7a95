/** Schema pieces shared by block params. */
import { z } from "zod";

const isNumberOrInfinity = (v: unknown): boolean => typeof v === "number" && !Number.isNaN(v);

/**
 * A number that may also be infinite (YAML `.inf` / `-.inf`). zod's `z.number()` rejects
 * infinities, and `z.literal(Infinity)` turns into `const: null` in JSON Schema; this one is
 * `{ "type": "number" }` there.
 */
export const extendedNumber = (): z.ZodType<number, number> =>
  z
    .unknown()
    .refine(isNumberOrInfinity, { message: "expected a number (.inf and -.inf are allowed)" })
    .meta({ type: "number" }) as unknown as z.ZodType<number, number>;

/** A 0-based index. */
export const index = () => z.number().int().min(0);
