"""Does PEFT read the adapter `tadslc finetune` wrote? The answer's loss on SFT examples,
the base model against the base model with the adapter.

The base is the same GGUF the adapter was trained on, loaded (and dequantized) by
Hugging Face transformers; the adapter directory is read by `peft.PeftModel`. An adapter
read wrongly (a tensor transposed, q's rows in another order, a missing scale) leaves the
loss near the base's; read rightly, it falls to what `finetune` reported. Prints one JSON
object: {"base": [loss per example], "adapted": [...]}.

    python peft_adapter.py ~/.cache/tadsl/models qwen2.5-coder-0.5b-instruct-q4_k_m.gguf \
        ADAPTER_DIR DATA/prompt_completion.jsonl
"""

import argparse
import json

import torch


def main():
    p = argparse.ArgumentParser()
    p.add_argument("model_dir")
    p.add_argument("gguf")
    p.add_argument("adapter")
    p.add_argument("data", help="sft-export's prompt_completion.jsonl")
    p.add_argument("--examples", type=int, default=4)
    a = p.parse_args()
    torch.set_num_threads(1)
    from peft import PeftModel
    from transformers import AutoModelForCausalLM, AutoTokenizer

    tokenizer = AutoTokenizer.from_pretrained(a.model_dir, gguf_file=a.gguf)
    model = AutoModelForCausalLM.from_pretrained(a.model_dir, gguf_file=a.gguf, dtype=torch.float32)
    with open(a.data) as f:
        examples = [json.loads(line) for line in f][: a.examples]

    def losses(m):
        out = []
        for ex in examples:
            prompt = tokenizer.apply_chat_template(ex["prompt"], tokenize=False, add_generation_prompt=True)
            full = prompt + ex["completion"][0]["content"] + tokenizer.eos_token
            ids = tokenizer(full, return_tensors="pt").input_ids
            labels = ids.clone()
            labels[:, : len(tokenizer(prompt).input_ids)] = -100  # the loss on the answer only
            with torch.no_grad():
                out.append(m(input_ids=ids, labels=labels).loss.item())
        return out

    base = losses(model)
    adapted = losses(PeftModel.from_pretrained(model, a.adapter))
    print(json.dumps({"base": base, "adapted": adapted}))


if __name__ == "__main__":
    main()
